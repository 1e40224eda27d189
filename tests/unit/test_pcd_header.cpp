// PCD headers are checked before Open3D reads them: regression tests for the
// inputs the fuzzer (tests/fuzz/fuzz_pcd) found, where a tiny file made Open3D
// allocate gigabytes or return made-up (0, 0, 0) points.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string Header(const std::string& fields, const std::string& size, const std::string& type,
                   int points, const std::string& data) {
  return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " + type +
         "\nCOUNT 1 1 1\nWIDTH " + std::to_string(points) + "\nHEIGHT 1\n" +
         "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(points) + "\nDATA " + data + "\n";
}

std::string LittleEndianU32(uint32_t value) {
  std::string bytes;
  for (int shift = 0; shift < 32; shift += 8) bytes.push_back(static_cast<char>(value >> shift));
  return bytes;
}

class PcdHeaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device random;
    dir_ = fs::path(::testing::TempDir()) / ("boicp_pcd_" + std::to_string(random()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  std::string Write(const std::string& bytes) const {
    const std::string path = (dir_ / "scan.pcd").string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  // The InputError message of loading `bytes` as a PCD ("" and a failure if none).
  std::string LoadError(const std::string& bytes) const {
    const std::string path = Write(bytes);
    try {
      LoadPointCloud(path);
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(path));
      return e.what();
    }
    ADD_FAILURE() << "expected InputError";
    return "";
  }

  fs::path dir_;
};

TEST_F(PcdHeaderTest, EveryPcdKindOpen3dWritesStillLoads) {
  const Points written = {Point(0.125, -0.75, 3.5), Point(-5.5, 6.25, -7.0), Point(1, 2, 4)};
  for (const bool ascii : {true, false}) {
    for (const bool compressed : {false, true}) {
      if (ascii && compressed) continue;
      const std::string path = (dir_ / "written.pcd").string();
      open3d::io::WritePointCloudOption option;
      option.write_ascii = open3d::io::WritePointCloudOption::IsAscii(ascii);
      option.compressed = open3d::io::WritePointCloudOption::Compressed(compressed);
      ASSERT_TRUE(open3d::io::WritePointCloud(path, open3d::geometry::PointCloud(written), option));
      const LoadedCloud cloud = LoadPointCloud(path);
      ASSERT_EQ(cloud.points.size(), written.size()) << ascii << compressed;
      for (size_t i = 0; i < written.size(); ++i) EXPECT_EQ(cloud.points[i], written[i]);
    }
  }
}

TEST_F(PcdHeaderTest, CompressedSizesBeyondTheFileAreRefusedBeforeAllocating) {
  // Found by fuzz_pcd: a 4 GB compressed size in a 200-byte file.
  const std::string header = Header("x y z", "4 4 4", "F F F", 1, "binary_compressed");
  EXPECT_THAT(LoadError(header + LittleEndianU32(0xFFFFFFF0u) + LittleEndianU32(12) + "abc"),
              HasSubstr("truncated PCD"));
  EXPECT_THAT(LoadError(header + LittleEndianU32(3) + LittleEndianU32(0xFFFFFFF0u) + "abc"),
              HasSubstr("binary_compressed sizes"));
}

// Open3D decodes binary data whole, so padding declared with COUNT (417
// bytes a point here) made a 24 MB file of 5 M points decode to 2 GB.
TEST_F(PcdHeaderTest, BinaryPointsOfMoreThan64BytesAreRefused) {
  std::string padded = Header("x y z _", "4 4 4 1", "F F F U", 2, "binary");
  padded.replace(padded.find("COUNT 1 1 1"), 11, "COUNT 1 1 1 417");
  EXPECT_THAT(LoadError(padded + std::string(2 * 429, '\0')),
              HasSubstr("binary points of 429 bytes; at most 64"));
  std::string pcl = Header("x y z _", "4 4 4 1", "F F F U", 2, "binary");
  pcl.replace(pcl.find("COUNT 1 1 1"), 11, "COUNT 1 1 1 52");  // 64 bytes: still read
  EXPECT_EQ(LoadPointCloud(Write(pcl + std::string(2 * 64, '\0'))).points.size(), 2u);
}

TEST_F(PcdHeaderTest, CompressedDataExpandingMoreThan16TimesIsRefused) {
  const std::string header = Header("x y z", "4 4 4", "F F F", 1000, "binary_compressed");
  EXPECT_THAT(
      LoadError(header + LittleEndianU32(600) + LittleEndianU32(12000) + std::string(600, '\0')),
      HasSubstr("would expand 20 times; at most 16"));
}

TEST_F(PcdHeaderTest, PointCountBeyondTheFileIsRefused) {
  EXPECT_THAT(LoadError(Header("x y z", "4 4 4", "F F F", 100000000, "binary") + "123456789012"),
              HasSubstr("truncated PCD"));
}

TEST_F(PcdHeaderTest, AsciiWithFewerLinesThanPointsIsRefusedNotZeroFilled) {
  // Open3D returned the missing points as (0, 0, 0).
  EXPECT_THAT(LoadError(Header("x y z", "4 4 4", "F F F", 3, "ascii") + "1 2 3\n4 5\n"),
              HasSubstr("1 complete point lines"));
  EXPECT_THAT(LoadError(Header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 two 3\n"),
              HasSubstr("'two' is not a number"));
}

TEST_F(PcdHeaderTest, BinaryDoubleCoordinatesAreRefusedNotZeroed) {
  // Open3D decodes only F4 floats; F8 coordinates came back as zeros.
  EXPECT_THAT(LoadError(Header("x y z", "8 8 8", "F F F", 1, "binary") + std::string(24, '\x40')),
              HasSubstr("binary x/y/z must be F4"));
}

TEST_F(PcdHeaderTest, MalformedHeadersNameTheProblem) {
  const std::string good = Header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 2 3\n";
  std::string reordered = good;
  reordered.replace(reordered.find("WIDTH 1\nHEIGHT 1"), 16, "HEIGHT 1\nWIDTH 1");
  EXPECT_THAT(LoadError(reordered), HasSubstr("out of order"));
  EXPECT_THAT(LoadError(Header("x y z", "4 4", "F F F", 1, "ascii") + "1 2 3\n"),
              HasSubstr("SIZE needs 3 values"));
  EXPECT_THAT(LoadError(Header("x y q", "4 4 4", "F F F", 1, "ascii") + "1 2 3\n"),
              HasSubstr("x, y and z"));
  EXPECT_THAT(LoadError(Header("x y z", "4 4 4", "F F F", 1, "lzma") + "1 2 3\n"),
              HasSubstr("DATA must be"));
  EXPECT_THAT(LoadError("VERSION 0.7\nFIELDS x y z\n"), HasSubstr("no DATA line"));
}

}  // namespace
}  // namespace boicp
