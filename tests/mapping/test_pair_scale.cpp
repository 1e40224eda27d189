// A pair's scale against its batch's: the median range read from a range
// profile, the dead zone within which a pair keeps the batch's settings, the
// power of two beyond it, and which settings follow the scale.

#include <cmath>

#include <gmock/gmock.h>

#include "boicp/mapping/pair_scale.hpp"

namespace boicp {
namespace {

using ::testing::ElementsAre;
using ::testing::StartsWith;

// A profile of points at `ranges` metres, one point each along +x.
RangeProfile ProfileAt(const std::vector<double>& ranges) {
  Points points;
  for (const double range : ranges) points.emplace_back(range, 0.0, 0.0);
  return ProfileRanges(points);
}

TEST(PairScale, MedianRangeIsTheMiddlePointsRangeToTheBinWidth) {
  const double median = MedianRange(ProfileAt({1.0, 2.0, 10.0, 10.5, 40.0}));
  EXPECT_GE(median, 10.0);
  EXPECT_LE(median, 10.0 * std::exp2(1.0 / 8.0));
  EXPECT_EQ(MedianRange(RangeProfile{}), 0.0);
}

TEST(PairScale, APairWithinTwiceTheReferenceKeepsTheBatchsSettings) {
  BatchScale scale;
  scale.reference_range = 10.0;
  scale.scan_ranges = {10.0, 19.0, 1.25, 1.25, 80.0, 0.0, 4.0};
  EXPECT_EQ(PairScaleStep(scale, {0, 1}), 0);   // 14.5 m
  EXPECT_EQ(PairScaleStep(scale, {2, 3}), -3);  // 1.25 m: an eighth
  EXPECT_EQ(PairScaleStep(scale, {4, 0}), 2);   // 45 m: 2.17 octaves
  EXPECT_EQ(PairScaleStep(scale, {6, 6}), -1);  // 4 m: 1.32 octaves below
  EXPECT_EQ(PairScaleStep(scale, {5, 2}), 0);   // a range unknown
  EXPECT_TRUE(ScanAtAnotherScale(scale, 2));
  EXPECT_FALSE(ScanAtAnotherScale(scale, 1));
  EXPECT_FALSE(ScanAtAnotherScale(scale, 5));
  EXPECT_THAT(DescribeScansAtAnotherScale(scale),  // 1.25, 1.25, 80 and 4 m
              StartsWith("4 of 7 scans reach over 2 times nearer or farther"));
  scale.reference_range = 0.0;  // settings not chosen from the scans
  EXPECT_EQ(PairScaleStep(scale, {2, 3}), 0);
  EXPECT_FALSE(ScanAtAnotherScale(scale, 2));
  EXPECT_EQ(DescribeScansAtAnotherScale(scale), "");
}

TEST(PairScale, OnlyTheLengthsChosenFromTheScansAreScaled) {
  const std::vector<RangeProfile> profiles = {ProfileAt({8.0, 9.0, 10.0}), ProfileAt({1.0}),
                                              ProfileAt({10.0, 11.0, 12.0})};
  const BatchScale scale = MeasureBatchScale(profiles, {0, 2}, kAutoRegistrationFields);
  EXPECT_NEAR(scale.reference_range, 11.0, 1.0);
  EXPECT_THAT(scale.fields,
              ElementsAre("voxel", "refine_voxel", "objective_truncation", "translation_bounds"));

  BoIcpConfig config;
  config.voxel = 0.8;
  config.retry_voxel = 3.2;
  config.refine_voxel = 0.1;
  config.objective_truncation = 1.2;
  config.translation_bounds = {8.0, 8.0, 1.6};
  config.rotation_bounds = {0.1, 0.1, M_PI};
  const BoIcpConfig eighth = ScaledConfig(config, scale, -3);
  EXPECT_DOUBLE_EQ(eighth.voxel, 0.1);
  EXPECT_DOUBLE_EQ(eighth.retry_voxel, 0.4);
  EXPECT_DOUBLE_EQ(eighth.refine_voxel, 0.0125);
  EXPECT_DOUBLE_EQ(eighth.objective_truncation, 0.15);
  EXPECT_EQ(eighth.translation_bounds, Eigen::Vector3d(1.0, 1.0, 0.2));
  EXPECT_EQ(eighth.rotation_bounds, config.rotation_bounds);

  // A voxel the user set is kept, and so is every other length.
  const BatchScale set_voxel =
      MeasureBatchScale(profiles, {0, 2}, {"refine_voxel", "translation_bounds"});
  EXPECT_EQ(set_voxel.reference_range, 0.0);
  EXPECT_TRUE(set_voxel.fields.empty());
  // A user-set refine voxel is kept while the voxel scales.
  const BatchScale set_refine = MeasureBatchScale(profiles, {0, 2}, {"voxel"});
  EXPECT_DOUBLE_EQ(ScaledConfig(config, set_refine, 1).refine_voxel, 0.1);
  EXPECT_DOUBLE_EQ(ScaledConfig(config, set_refine, 1).voxel, 1.6);
  // A measured scan without a profile (stored before profiles were): no scaling.
  EXPECT_EQ(MeasureBatchScale({RangeProfile{}, profiles[1]}, {0, 1}, kAutoRegistrationFields)
                .reference_range,
            0.0);
}

}  // namespace
}  // namespace boicp
