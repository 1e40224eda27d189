// The map's scan cache: each scan loaded and downsampled once for the pairs
// that share it, with the answers of registering the raw scans.

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/scan_pyramid_cache.hpp"
#include "boicp/registration/bo_icp.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;

class ScanPyramidCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_pyramids_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    const SyntheticDrive drive(4, 3);
    for (int i = 0; i < drive.size(); ++i) {
      ScanSource scan;
      scan.path = (dir_ / ("scan_" + std::to_string(i) + ".xyz")).string();
      WriteXyz(scan.path, drive.Scan(i).points);
      scans_.push_back(scan);
    }
    config_ = PresetConfig("C");
    config_.automatic.clear();
    config_.voxel = 0.8;
    config_.refine_voxel = 0.2;
    config_.translation_bounds = Eigen::Vector3d(5.0, 5.0, 1.5);
    config_.rotation_bounds = Eigen::Vector3d(0.2, 0.2, M_PI);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Points Raw(int index) const { return LoadPointCloud(scans_[index].path).points; }

  fs::path dir_;
  std::vector<ScanSource> scans_;
  BoIcpConfig config_;
};

TEST_F(ScanPyramidCacheTest, ServesEachScansPyramidAndBuildsADroppedOneAgainTheSame) {
  ScanPyramidCache cache(scans_, config_, 2);
  const std::shared_ptr<const ScanPyramid> first = cache.Get(1);
  const ScanPyramid built = BuildScanPyramid(Raw(1), config_);
  ASSERT_EQ(first->levels.size(), built.levels.size());
  EXPECT_EQ(first->centre, built.centre);
  for (size_t k = 0; k < built.levels.size(); ++k) EXPECT_EQ(first->levels[k], built.levels[k]);
  EXPECT_EQ(cache.Get(1), first);  // kept: the same object
  cache.Get(2);
  cache.Get(3);  // scan 1 is now the least recent of three: dropped
  const std::shared_ptr<const ScanPyramid> again = cache.Get(1);
  EXPECT_NE(again, first);
  EXPECT_EQ(again->levels, first->levels);
  EXPECT_THROW(cache.Get(4), InputError);
  EXPECT_THROW(cache.Get(-1), InputError);
}

TEST_F(ScanPyramidCacheTest, ThreadsAskingForOneScanShareOneBuild) {
  ScanPyramidCache cache(scans_, config_, 4);
  std::vector<std::shared_ptr<const ScanPyramid>> got(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < got.size(); ++t) threads.emplace_back([&, t] { got[t] = cache.Get(2); });
  for (std::thread& thread : threads) thread.join();
  for (const auto& pyramid : got) EXPECT_EQ(pyramid, got[0]);
}

TEST_F(ScanPyramidCacheTest, ABatchPairFromTheCacheIsThePairFromTheRawScans) {
  for (const Budget budget : {Budget::kAuto, Budget::kFixed}) {
    BoIcpConfig config = config_;
    config.budget = budget;
    config.random_samples = 8;
    config.iterations = 8;
    ScanPyramidCache cache(scans_, config, 2);
    for (const PairIndex pair : {PairIndex{0, 1}, PairIndex{1, 2}, PairIndex{0, 2}}) {
      const BatchPairResult cached = RegisterBatchPair(scans_, pair, config, cache);
      BoIcpConfig raw_config = config;
      raw_config.seed = cached.seed;
      const std::optional<Transform> guess = std::abs(pair.target - pair.source) == 1
                                                 ? std::optional<Transform>(Transform::Identity())
                                                 : std::nullopt;
      const RegistrationResult raw =
          RegisterPair(Raw(pair.source), Raw(pair.target), raw_config, std::nullopt, {}, guess);
      EXPECT_EQ(cached.registration.transform, raw.transform)
          << pair.source << " -> " << pair.target;
      EXPECT_EQ(cached.registration.confidence, raw.confidence);
      EXPECT_EQ(cached.registration.evaluations, raw.evaluations);
    }
  }
  ScanPyramidCache cache(scans_, config_, 2);
  const std::shared_ptr<const ScanPyramid> scan = cache.Get(0);
  BoIcpConfig automatic = config_;
  automatic.automatic = {"voxel"};
  EXPECT_THROW(RegisterPair(*scan, *scan, automatic, std::nullopt), std::invalid_argument);
  // The budgets order a pyramid's points differently (CellOrder).
  BoIcpConfig fixed = config_;
  fixed.budget = Budget::kFixed;
  EXPECT_THROW(RegisterPair(*scan, *scan, fixed, std::nullopt), std::invalid_argument);
}

}  // namespace
}  // namespace boicp
