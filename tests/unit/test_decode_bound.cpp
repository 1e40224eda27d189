// DecodeBoundBytes: what decoding a scan may allocate, from its header, for
// every format; and LoadPointCloud holding that much of a decode budget for
// as long as the cloud lives.

#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <iostream>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/ImageIO.h>
#include <open3d/io/PointCloudIO.h>

#include "../support/sanitized_build.hpp"
#include "boicp/io/decode_budget.hpp"
#include "boicp/io/point_cloud_io.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr uint64_t kVector = 24;  // an Eigen::Vector3d

// A field of /proc/self/status, in bytes (0 when missing).
uint64_t StatusBytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stoull(line.substr(field.size() + 1)) << 10;
  }
  return 0;
}

constexpr uint64_t kCannotMeasure = ~uint64_t{0};
constexpr uint64_t kLoadFailed = kCannotMeasure - 1;

// How far the resident memory of a child process rose above where it started
// while it loaded `path`: kLoadFailed when the load threw or kept no point,
// kCannotMeasure when the kernel cannot reset the high-water mark.
uint64_t PeakGrowthOfLoadInChild(const std::string& path, const LoadOptions& options) {
  int fds[2];
  if (::pipe(fds) != 0) return kCannotMeasure;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    uint64_t growth = kCannotMeasure;
    // Memory the parent freed, still resident, would hide the load's.
    ::malloc_trim(0);
    // Writing 5 resets VmHWM to the current resident size.
    if (std::ofstream("/proc/self/clear_refs") << "5") {
      const uint64_t start = StatusBytes("VmRSS");
      try {
        const bool loaded = !LoadPointCloud(path, options).points.empty();
        growth = loaded ? StatusBytes("VmHWM") - start : kLoadFailed;
      } catch (...) {
        growth = kLoadFailed;
      }
    }
    const ssize_t written = ::write(fds[1], &growth, sizeof(growth));
    ::_exit(written == sizeof(growth) ? 0 : 1);
  }
  ::close(fds[1]);
  uint64_t growth = kLoadFailed;  // the child died without answering
  const ssize_t got = ::read(fds[0], &growth, sizeof(growth));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return got == sizeof(growth) ? growth : kLoadFailed;
}

class DecodeBoundTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("boicp_decode_bound_" + std::to_string(std::random_device()()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  // `n` points written by Open3D as `name` (its extension picks the format),
  // with normals and colours when asked.
  std::string WriteCloud(const std::string& name, size_t n, bool normals_and_colors,
                         bool compressed = false) const {
    open3d::geometry::PointCloud cloud;
    std::mt19937 random(7);
    std::uniform_real_distribution<double> uniform(-10.0, 10.0);
    for (size_t i = 0; i < n; ++i) {
      cloud.points_.emplace_back(uniform(random), uniform(random), uniform(random));
      if (normals_and_colors) {
        cloud.normals_.emplace_back(0.0, 0.0, 1.0);
        cloud.colors_.emplace_back(0.5, 0.25, 1.0);
      }
    }
    const std::string path = (dir_ / name).string();
    open3d::io::WritePointCloudOption option;
    option.compressed = open3d::io::WritePointCloudOption::Compressed(compressed);
    EXPECT_TRUE(open3d::io::WritePointCloud(path, cloud, option));
    return path;
  }

  std::string WriteBytes(const std::string& name, const std::string& bytes) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  fs::path dir_;
};

TEST_F(DecodeBoundTest, CompressedPcdCountsBothBuffersAndThePoints) {
  const std::string small = WriteCloud("small.pcd", 1000, false, true);
  const std::string large = WriteCloud("large.pcd", 4000, false, true);
  const uint64_t small_bound = DecodeBoundBytes(small);
  const uint64_t large_bound = DecodeBoundBytes(large);
  // 12 bytes a point inflated, about as many compressed, and 24 kept.
  EXPECT_GE(small_bound, 1000 * (12 + kVector));
  EXPECT_LE(small_bound, 1000 * (12 + kVector) + fs::file_size(small));
  EXPECT_GE(large_bound, 4 * small_bound - 4 * 1000);
  EXPECT_LE(large_bound, 4 * small_bound + 4 * 1000);
  // Normals and colours: 28 bytes a point inflated, three vectors kept.
  const std::string rich = WriteCloud("rich.pcd", 1000, true, true);
  EXPECT_GE(DecodeBoundBytes(rich), 1000 * (28 + 3 * kVector));
}

TEST_F(DecodeBoundTest, BinaryAndAsciiPcdCountTheirArrays) {
  // Open3D reads binary data a point at a time, so the arrays dominate.
  const std::string binary = WriteCloud("binary.pcd", 2000, false);
  EXPECT_GE(DecodeBoundBytes(binary), 2000 * kVector);
  EXPECT_LE(DecodeBoundBytes(binary), 2000 * kVector + 64);
  const std::string rich = WriteCloud("rich.pcd", 2000, true);
  EXPECT_GE(DecodeBoundBytes(rich), 2000 * 3 * kVector);
  const std::string ascii =
      WriteBytes("ascii.pcd",
                 "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\n"
                 "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n");
  // Ascii lines are read one at a time: the points and a line.
  EXPECT_GE(DecodeBoundBytes(ascii), 2 * kVector);
  EXPECT_LE(DecodeBoundBytes(ascii), 2 * kVector + 4096);
}

TEST_F(DecodeBoundTest, PlyCountsTheArraysItsPropertiesAsk) {
  const std::string plain = WriteCloud("plain.ply", 3000, false);
  const std::string rich = WriteCloud("rich.ply", 3000, true);
  EXPECT_EQ(DecodeBoundBytes(plain), 3000 * kVector);
  EXPECT_EQ(DecodeBoundBytes(rich), 3000 * 3 * kVector);
}

TEST_F(DecodeBoundTest, KittiXyzAndDepthPngBoundsFollowTheirSizes) {
  const std::string kitti = WriteBytes("scan.bin", std::string(16 * 500, '\0'));
  EXPECT_EQ(DecodeBoundBytes(kitti), 16 * 500 + 500 * kVector);  // the file read whole
  const std::string xyz = WriteBytes("scan.xyz", "# x y z\n1 2 3\n\n4 5 6\n7 8 9\n");
  EXPECT_GE(DecodeBoundBytes(xyz), 3 * kVector);
  EXPECT_LE(DecodeBoundBytes(xyz), 3 * kVector + 4096);

  open3d::geometry::Image image;
  image.Prepare(64, 48, 1, 2);
  const std::string png = (dir_ / "depth.png").string();
  ASSERT_TRUE(open3d::io::WriteImage(png, image));
  EXPECT_EQ(DecodeBoundBytes(png), 64 * 48 * (2 + kVector));
}

TEST_F(DecodeBoundTest, HeaderErrorsAreTheLoadersOwn) {
  const std::string plain = WriteCloud("plain.ply", 3000, false);
  LoadOptions options;
  options.max_points = 2999;
  EXPECT_THROW(DecodeBoundBytes(plain, options), PointLimitError);
  const std::string truncated =
      WriteBytes("short.pcd",
                 "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 100\n"
                 "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 100\nDATA binary\n" +
                     std::string(12, '\0'));
  EXPECT_THROW(DecodeBoundBytes(truncated), InputError);
  EXPECT_THROW(DecodeBoundBytes((dir_ / "missing.pcd").string()), InputError);
}

// The bound against what a load really takes: the peak resident growth of a
// process that loads the scan (its allocations, touched) may not pass the
// bound by more than the allocator's and the readers' small buffers, and
// must be most of it (else the measurement saw nothing).
TEST_F(DecodeBoundTest, ALoadNeverTakesMuchMoreThanItsBound) {
  if (kSanitizedBuild) GTEST_SKIP() << "a sanitizer's allocator inflates resident memory";
  constexpr uint64_t kSmallBuffers = 8u << 20;
  std::string xyz;
  for (int i = 0; i < 1000000; ++i) xyz += "1 2 3\n";
  open3d::geometry::Image depth;
  depth.Prepare(2000, 1500, 1, 2);
  for (size_t i = 0; i < depth.data_.size(); i += 2) depth.data_[i + 1] = 0x03;  // 768 (LE)
  const std::string png = (dir_ / "depth.png").string();
  ASSERT_TRUE(open3d::io::WriteImage(png, depth));
  const std::vector<std::string> scans = {
      WriteCloud("compressed.pcd", 2000000, false, true),
      WriteCloud("rich_compressed.pcd", 1000000, true, true),
      WriteCloud("binary.pcd", 2000000, false),
      WriteCloud("rich.ply", 1000000, true),
      WriteBytes("scan.bin", std::string(16 * 2000000, '\0')),
      WriteBytes("scan.xyz", xyz),
      png,
  };
  LoadOptions options;
  options.depth.intrinsics = Intrinsics{500.0, 500.0, 1000.0, 750.0};
  options.depth.depth_scale = 1000.0;
  for (const std::string& path : scans) {
    const uint64_t bound = DecodeBoundBytes(path, options);
    const uint64_t growth = PeakGrowthOfLoadInChild(path, options);
    if (growth == kCannotMeasure) GTEST_SKIP() << "cannot reset VmHWM (/proc/self/clear_refs)";
    ASSERT_NE(growth, kLoadFailed) << path << " did not load";
    std::cout << fs::path(path).filename().string() << ": bound " << (bound >> 20)
              << " MiB, peak growth " << (growth >> 20) << " MiB\n";
    EXPECT_LE(growth, bound + kSmallBuffers) << path;
    EXPECT_GE(growth, bound / 2) << path;
  }
}

TEST_F(DecodeBoundTest, ALoadedCloudHoldsItsBoundUntilItIsDestroyed) {
  const std::string path = WriteCloud("scan.pcd", 5000, false, true);
  const uint64_t bound = DecodeBoundBytes(path);
  DecodeBudget budget(bound);
  LoadOptions options;
  options.decode_budget = &budget;
  {
    const LoadedCloud cloud = LoadPointCloud(path, options);
    EXPECT_EQ(cloud.points.size(), 5000u);
    EXPECT_EQ(cloud.decode_lease.bytes(), bound);
    EXPECT_EQ(budget.held_bytes(), bound);
  }
  EXPECT_EQ(budget.held_bytes(), 0u);
}

TEST_F(DecodeBoundTest, AScanOverTheWholeBudgetIsRefusedBeforeDecoding) {
  const std::string path = WriteCloud("scan.pcd", 5000, false, true);
  DecodeBudget budget(DecodeBoundBytes(path) - 1);
  LoadOptions options;
  options.decode_budget = &budget;
  try {
    LoadPointCloud(path, options);
    FAIL() << "expected LimitExceeded";
  } catch (const LimitExceeded& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr(path), HasSubstr("(--max-decode-mb)")));
  }
  EXPECT_EQ(budget.held_bytes(), 0u);
}

TEST_F(DecodeBoundTest, AStoppedLoadWaitingForTheBudgetThrowsCancelled) {
  const std::string path = WriteCloud("scan.pcd", 100, false);
  DecodeBudget budget(DecodeBoundBytes(path));
  const DecodeBudget::Lease taken = budget.Acquire(1);  // the scan cannot fit beside it
  LoadOptions options;
  options.decode_budget = &budget;
  options.decode_stop = [] { return true; };
  EXPECT_THROW(LoadPointCloud(path, options), Cancelled);
  EXPECT_EQ(budget.held_bytes(), 1u);
}

}  // namespace
}  // namespace boicp
