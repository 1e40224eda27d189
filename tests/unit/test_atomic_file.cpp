// Atomic file writes: a reader sees the old file or the whole new one, a
// failed write leaves the old file and no staging file, and the error names
// the file.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/util/atomic_file.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;

std::string Contents(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> Entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  return names;
}

class AtomicFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_atomic_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(AtomicFile, ReplacesTheFileAndLeavesNothingBeside) {
  const fs::path path = dir_ / "pairs.json";
  WriteTextFileAtomically(path, "old");
  WriteTextFileAtomically(path, "new contents");
  EXPECT_EQ(Contents(path), "new contents");
  EXPECT_THAT(Entries(dir_), ::testing::ElementsAre("pairs.json"));
}

TEST_F(AtomicFile, AFailedWriteKeepsTheOldFileAndRemovesTheStagingFile) {
  const fs::path path = dir_ / "trajectory.tum";
  WriteTextFileAtomically(path, "old");
  std::string staged;
  EXPECT_THROW(WriteFileAtomically(path,
                                   [&](const std::string& staging) {
                                     staged = staging;
                                     std::ofstream(staging) << "half";
                                     throw std::runtime_error("disk full");
                                   }),
               std::runtime_error);
  EXPECT_EQ(fs::path(staged).parent_path(), dir_);
  EXPECT_EQ(Contents(path), "old");
  EXPECT_THAT(Entries(dir_), ::testing::ElementsAre("trajectory.tum"));
}

TEST_F(AtomicFile, AnErrorNamesTheFile) {
  const fs::path path = dir_ / "missing folder" / "map.bt";
  try {
    WriteTextFileAtomically(path, "x");
    FAIL() << "wrote into a folder that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr(path.string()));
  }
}

TEST_F(AtomicFile, WritersOnSeveralThreadsNeverTearTheFile) {
  const fs::path path = dir_ / "shared.txt";
  const std::string a(100000, 'a'), b(100000, 'b');
  std::vector<std::thread> writers;
  for (int t = 0; t < 4; ++t) {
    writers.emplace_back([&, t] {
      for (int i = 0; i < 10; ++i) WriteTextFileAtomically(path, t % 2 == 0 ? a : b);
    });
  }
  for (std::thread& writer : writers) writer.join();
  const std::string last = Contents(path);
  EXPECT_TRUE(last == a || last == b);
  EXPECT_THAT(Entries(dir_), ::testing::ElementsAre("shared.txt"));
}

}  // namespace
}  // namespace boicp
