// The map's scan cache: each scan loaded and prepared once for the pairs
// that share it, with the answers of registering the raw scans.

#include <unistd.h>

#include <atomic>
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
#include "boicp/mapping/prepared_scan_cache.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "boicp/registration/refinement.hpp"
#include "boicp/registration/registration_method.hpp"
#include "evaluation.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;

class PreparedScanCacheTest : public ::testing::Test {
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

// The engine's methods keep a scan as its pyramid; a counting method shows
// how often the cache prepares.
class CountingMethod final : public RegistrationMethod {
 public:
  std::string Describe() const override { return "counts preparations"; }
  std::shared_ptr<const PreparedScan> Prepare(PointSpan scan) const override {
    ++prepared;
    return std::make_shared<const Counted>(scan.size());
  }
  RegistrationResult Register(const PreparedScan&, const PreparedScan&, const PairHints&,
                              const RegistrationCallbacks&) const override {
    return {};
  }
  struct Counted final : PreparedScan {
    explicit Counted(size_t n) : points(n) {}
    size_t points;
  };
  mutable std::atomic<int> prepared{0};
};

TEST_F(PreparedScanCacheTest, ServesEachScanPreparedAndPreparesADroppedOneAgainTheSame) {
  CountingMethod method;
  PreparedScanCache cache(scans_, method, 2);
  const std::shared_ptr<const PreparedScan> first = cache.Get(1);
  EXPECT_EQ(dynamic_cast<const CountingMethod::Counted&>(*first).points, Raw(1).size());
  EXPECT_EQ(cache.Get(1), first);  // kept: the same object
  EXPECT_EQ(method.prepared, 1);
  cache.Get(2);
  cache.Get(3);  // scan 1 is now the least recent of three: dropped
  const std::shared_ptr<const PreparedScan> again = cache.Get(1);
  EXPECT_NE(again, first);
  EXPECT_EQ(method.prepared, 4);
  EXPECT_EQ(dynamic_cast<const CountingMethod::Counted&>(*again).points, Raw(1).size());
  EXPECT_THROW(cache.Get(4), InputError);
  EXPECT_THROW(cache.Get(-1), InputError);
}

TEST_F(PreparedScanCacheTest, ThreadsAskingForOneScanShareOnePreparation) {
  CountingMethod method;
  PreparedScanCache cache(scans_, method, 4);
  std::vector<std::shared_ptr<const PreparedScan>> got(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < got.size(); ++t) threads.emplace_back([&, t] { got[t] = cache.Get(2); });
  for (std::thread& thread : threads) thread.join();
  for (const auto& prepared : got) EXPECT_EQ(prepared, got[0]);
  EXPECT_EQ(method.prepared, 1);
}

TEST_F(PreparedScanCacheTest, ABatchPairFromTheCacheIsThePairFromTheRawScans) {
  for (const Budget budget : {Budget::kAuto, Budget::kFixed}) {
    BoIcpConfig config = config_;
    config.budget = budget;
    config.random_samples = 8;
    config.iterations = 8;
    const auto method = CoreMethods().Create(config.method, config);
    PreparedScanCache cache(scans_, *method, 2);
    for (const PairIndex pair : {PairIndex{0, 1}, PairIndex{1, 2}, PairIndex{0, 2}}) {
      const PairResult cached = RegisterBatchPair(scans_, pair, config, cache);
      BoIcpConfig raw_config = config;
      raw_config.seed = cached.seed;
      const std::optional<Transform> guess = std::abs(pair.target - pair.source) == 1
                                                 ? std::optional<Transform>(Transform::Identity())
                                                 : std::nullopt;
      const RegistrationResult raw =
          RegisterPair(Raw(pair.source), Raw(pair.target), raw_config, std::nullopt, {}, guess);
      EXPECT_EQ(cached.transform, raw.transform) << pair.source << " -> " << pair.target;
      EXPECT_EQ(cached.confidence, raw.confidence);
      EXPECT_EQ(cached.evaluations, raw.evaluations);
    }
  }
  const ScanPyramid scan = BuildScanPyramid(Raw(0), config_);
  BoIcpConfig automatic = config_;
  automatic.automatic = {"voxel"};
  EXPECT_THROW(RegisterPair(scan, scan, automatic, std::nullopt), std::invalid_argument);
  EXPECT_THROW(CoreMethods().Create(kDefaultMethod, automatic), std::invalid_argument);
  // The budgets order a pyramid's points differently (CellOrder).
  BoIcpConfig fixed = config_;
  fixed.budget = Budget::kFixed;
  EXPECT_THROW(RegisterPair(scan, scan, fixed, std::nullopt), std::invalid_argument);
}

// A batch whose method is "icp" registers each neighbouring pair with one
// refinement from the identity guess, within 0.5 degrees and 5 cm here.
TEST_F(PreparedScanCacheTest, AnIcpBatchRefinesEachNeighbouringPairOnceFromTheIdentity) {
  BoIcpConfig config = config_;
  config.method = "icp";
  const auto method = CoreMethods().Create(config.method, config);
  PreparedScanCache cache(scans_, *method, 2);
  const SyntheticDrive drive(4, 3);
  for (const PairIndex pair : {PairIndex{0, 1}, PairIndex{1, 2}, PairIndex{2, 3}}) {
    const PairResult r = RegisterBatchPair(scans_, pair, config, cache);
    const Transform truth = drive.Pose(pair.target).inverse() * drive.Pose(pair.source);
    EXPECT_EQ(r.evaluations, 1);
    EXPECT_EQ(r.answered_by, Rung::kPrior);
    EXPECT_LT(RotationErrorDeg(r.transform, truth), 0.5) << pair.source << " -> " << pair.target;
    EXPECT_LT(TranslationErrorM(r.transform, truth), 0.05);
  }
}

}  // namespace
}  // namespace boicp
