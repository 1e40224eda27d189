// A trajectory against its reference (core/mapping/trajectory_error).

#include <cmath>

#include <gtest/gtest.h>

#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/trajectory_error.hpp"

namespace boicp {
namespace {

// 21 poses along a 20 m straight line, one a metre, turning gently.
std::vector<std::optional<Transform>> Line() {
  std::vector<std::optional<Transform>> poses;
  for (int i = 0; i <= 20; ++i) {
    poses.push_back(PoseFromYawTranslation(0.01 * i, {1.0 * i, 0.0, 0.0}));
  }
  return poses;
}

std::vector<Transform> Known(const std::vector<std::optional<Transform>>& poses) {
  std::vector<Transform> known;
  for (const auto& pose : poses) known.push_back(*pose);
  return known;
}

TEST(CompareTrajectories, ARigidlyMovedCopyHasNoError) {
  const std::vector<std::optional<Transform>> reference = Line();
  std::vector<Transform> moved = Known(reference);
  const Transform frame = PoseFromYawTranslation(1.2, {100.0, -40.0, 3.0});
  for (Transform& pose : moved) pose = frame * pose;
  const TrajectoryError error = CompareTrajectories(moved, reference);
  EXPECT_EQ(error.scans, 21);
  EXPECT_LT(error.ate_rmse, 1e-9);
  EXPECT_LT(error.drift_per_metre, 1e-9);
  EXPECT_NEAR(error.segment, 2.0, 1e-9);  // a tenth of the 20 m path
  EXPECT_EQ(error.segments, 19);
}

TEST(CompareTrajectories, MeasuresAnOffsetScanAndDrift) {
  const std::vector<std::optional<Transform>> reference = Line();
  // Every step 1 % longer than it was: 1 cm of drift per metre.
  std::vector<Transform> stretched = Known(reference);
  for (Transform& pose : stretched) pose(0, 3) *= 1.01;
  const TrajectoryError drift = CompareTrajectories(stretched, reference, 5.0);
  EXPECT_NEAR(drift.drift_per_metre, 0.01, 1e-3);
  EXPECT_EQ(drift.segments, 16);

  // One scan 0.5 m off sideways, the others exact: the alignment barely
  // moves, so that scan carries almost all of the error.
  std::vector<Transform> one_off = Known(reference);
  one_off[10](1, 3) += 0.5;
  const TrajectoryError offset = CompareTrajectories(one_off, reference);
  EXPECT_NEAR(offset.ate_max, 0.5, 0.05);
  EXPECT_NEAR(offset.per_scan[10], offset.ate_max, 1e-12);
  EXPECT_NEAR(offset.ate_rmse, 0.5 / std::sqrt(21.0), 0.02);
}

TEST(CompareTrajectories, SkipsScansWithoutAReferenceAndRefusesTooFew) {
  std::vector<std::optional<Transform>> reference = Line();
  reference[3].reset();
  const std::vector<Transform> poses = Known(Line());
  const TrajectoryError error = CompareTrajectories(poses, reference);
  EXPECT_EQ(error.scans, 20);
  EXPECT_TRUE(std::isnan(error.per_scan[3]));
  EXPECT_THROW(CompareTrajectories(poses, {reference.begin(), reference.begin() + 2}), InputError);
  std::vector<std::optional<Transform>> one(21);
  one[0] = Transform::Identity();
  EXPECT_THROW(CompareTrajectories(poses, one), InputError);

  // Two scans align rigidly: a moved copy has no error, a longer step has.
  const std::vector<std::optional<Transform>> pair = {reference[0], reference[4]};
  const Transform frame = PoseFromYawTranslation(0.7, {5.0, 2.0, 0.0});
  EXPECT_LT(CompareTrajectories({frame * *pair[0], frame * *pair[1]}, pair).ate_rmse, 1e-9);
  Transform longer = *pair[1];
  longer(0, 3) += 1.0;
  EXPECT_NEAR(CompareTrajectories({*pair[0], longer}, pair).ate_rmse, 0.5, 1e-9);
}

}  // namespace
}  // namespace boicp
