// A scan's feature cloud: its voxel coarsens by sqrt(2) per doubling of the
// scan's points, it is computed once whoever asks first, and it does not
// depend on the thread count.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/scan_features.hpp"

namespace boicp {
namespace {

constexpr double kVoxel = 0.5;  // metres

Points StreetScan() {
  return SimulateScan(MakeSyntheticStreet(3, 15.0), PoseFromYawTranslation(0.4, {1.0, 0.0, 1.8}),
                      30.0, 0.01, 7);
}

TEST(ScanFeatures, StepCoarsensBySqrtTwoPerDoublingOfPoints) {
  EXPECT_EQ(FeatureStep(0), 0);
  EXPECT_EQ(FeatureStep(4000), 0);
  EXPECT_EQ(FeatureStep(5000), 0);  // log2(1.25) rounds to 0
  EXPECT_EQ(FeatureStep(8000), 1);
  EXPECT_EQ(FeatureStep(16000), 2);
  EXPECT_EQ(FeatureStep(1000000), 8);
  EXPECT_EQ(FeatureVoxel(kVoxel, 0), kVoxel);
  EXPECT_EQ(FeatureVoxel(kVoxel, 2), 2 * kVoxel);
  EXPECT_EQ(FeatureVoxel(kVoxel, 4), 4 * kVoxel);
  EXPECT_NEAR(FeatureVoxel(kVoxel, 1), kVoxel * std::sqrt(2.0), 1e-15);
}

TEST(ScanFeatures, CloudIsTheScanAtTheStepsVoxelWithAFeatureAPoint) {
  const Points scan = StreetScan();
  const ScanFeatures fine = ComputeScanFeatures(scan, kVoxel, 0, 1);
  const ScanFeatures coarse = ComputeScanFeatures(scan, kVoxel, 2, 1);
  EXPECT_EQ(fine.voxel, kVoxel);
  EXPECT_EQ(coarse.voxel, 2 * kVoxel);
  EXPECT_EQ(fine.features.cols(), static_cast<Eigen::Index>(fine.points.size()));
  EXPECT_EQ(coarse.features.cols(), static_cast<Eigen::Index>(coarse.points.size()));
  // A surface's points fall with the square of the voxel: a quarter or so
  // (more where a scan's returns are sparse already).
  EXPECT_LT(coarse.points.size(), fine.points.size() / 2);
  EXPECT_GT(coarse.points.size(), fine.points.size() / 6);
}

TEST(ScanFeatureMemo, EveryCallerOfAStepGetsTheOneComputationWhateverTheThreads) {
  const Points scan = StreetScan();
  ScanFeatureMemo memo;
  std::vector<std::shared_ptr<const ScanFeatures>> got(4);
  std::vector<std::thread> callers;
  for (size_t i = 0; i < got.size(); ++i) {
    callers.emplace_back([&, i] { got[i] = memo.At(scan, kVoxel, 1, 1 + static_cast<int>(i)); });
  }
  for (std::thread& caller : callers) caller.join();
  EXPECT_EQ(memo.computed(), 1u);
  for (const auto& features : got) EXPECT_EQ(features.get(), got[0].get());

  const ScanFeatures serial = ComputeScanFeatures(scan, kVoxel, 1, 1);
  EXPECT_TRUE(got[0]->points == serial.points);
  EXPECT_TRUE(got[0]->features == serial.features);

  EXPECT_NE(memo.At(scan, kVoxel, 0, 2).get(), got[0].get());
  EXPECT_EQ(memo.computed(), 2u);
  EXPECT_EQ(memo.At(scan, kVoxel, 1, 2).get(), got[0].get());
  EXPECT_EQ(memo.computed(), 2u);
}

}  // namespace
}  // namespace boicp
