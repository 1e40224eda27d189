// `boicp register` and `boicp map` given files whose headers declare far more
// points than the loaders' limit, or more bytes than the file holds: each is
// refused from its header with exit code 2 and one error line, and the
// process stays small.

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>

#include <gmock/gmock.h>

#include "../support/files_and_processes.hpp"
#include "../support/memory_bombs.hpp"

namespace boicp::test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr uint64_t kPeakRssLimitMb = 300;

class MemoryBombsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("boicp_bombs_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    bombs_ = WriteMemoryBombs(dir_);
    ASSERT_EQ(RunCaptured(std::string(BOICP_CLI_PATH) + " demo-data --out " + dir_.string(), dir_)
                  .exit_code,
              0);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void ExpectRefused(const std::string& what, const std::vector<std::string>& argv,
                     const std::string& refusal = "") {
    const MeasuredRun run = RunMeasured(argv, dir_ / "stderr");
    std::cout << what << ": exit " << run.exit_code << ", peak RSS " << run.peak_rss_mb << " MB\n";
    EXPECT_EQ(run.exit_code, 2) << what << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << what << ": " << run.err;
    EXPECT_THAT(run.err, HasSubstr(refusal.empty() ? "over the limit of 5000000" : refusal))
        << what;
    EXPECT_LT(run.peak_rss_mb, kPeakRssLimitMb) << what;
  }

  fs::path dir_;
  std::vector<MemoryBomb> bombs_;
};

TEST_F(MemoryBombsCli, RegisterRefusesEachBombFromItsHeader) {
  for (const MemoryBomb& bomb : bombs_) {
    ExpectRefused("register " + bomb.name,
                  {BOICP_CLI_PATH, "register", "--source", (dir_ / bomb.file_name).string(),
                   "--target", (dir_ / "target.xyz").string(), "--intrinsics", "500,500,4096,4096",
                   "--depth-scale", "1000"},
                  bomb.refusal);
  }
}

TEST_F(MemoryBombsCli, MapRefusesAFolderHoldingABomb) {
  const fs::path folder = dir_ / "scans";
  fs::create_directories(folder);
  fs::copy_file(dir_ / "source.xyz", folder / "a.xyz");
  fs::copy_file(dir_ / "bomb.xyz", folder / "b.xyz");  // one format a folder
  ExpectRefused("map with an XYZ bomb",
                {BOICP_CLI_PATH, "map", folder.string(), "-o", (dir_ / "out").string()});
}

}  // namespace
}  // namespace boicp::test
