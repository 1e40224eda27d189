// Pose chaining and pose-graph optimisation (core/pose_graph).

#include <random>

#include <gtest/gtest.h>

#include "boicp/evaluation.hpp"
#include "boicp/pose_graph.hpp"
#include "boicp/synthetic_scene.hpp"

namespace boicp {
namespace {

Transform Pose(double yaw, double x, double y) {
  return PoseFromYawTranslation(yaw, Eigen::Vector3d(x, y, 0.0));
}

// T_target_source between two world poses.
Transform Relative(const Transform& T_world_target, const Transform& T_world_source) {
  return T_world_target.inverse() * T_world_source;
}

// A loop: 8 poses on a circle of radius 10 m.
std::vector<Transform> Circle() {
  std::vector<Transform> poses;
  for (int i = 0; i < 8; ++i) {
    const double a = 2.0 * M_PI * i / 8;
    poses.push_back(Pose(a + M_PI / 2, 10 * std::cos(a), 10 * std::sin(a)));
  }
  return poses;
}

TEST(ChainPoses, FollowsEdgesInEitherDirection) {
  const std::vector<Transform> truth = {Pose(0, 0, 0), Pose(0.3, 2, 0), Pose(0.5, 4, 1)};
  std::vector<PairConstraint> constraints = {
      {{0, 1}, Relative(truth[1], truth[0])},  // source 0 onto target 1
      {{2, 1}, Relative(truth[1], truth[2])},  // source 2 onto target 1
  };
  const ChainedPoses chained = ChainPoses(3, constraints);
  ASSERT_EQ(chained.poses.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(RotationErrorDeg(chained.poses[i], truth[i]), 1e-9);
    EXPECT_LT(TranslationErrorM(chained.poses[i], truth[i]), 1e-9);
  }
  EXPECT_EQ(chained.loop_closures, 0);
}

TEST(ChainPoses, AnchorsScanZeroAndPrefersEarlierEdges) {
  const std::vector<Transform> truth = Circle();
  std::vector<PairConstraint> constraints;
  for (int i = 0; i + 1 < 8; ++i)
    constraints.push_back({{i, i + 1}, Relative(truth[i + 1], truth[i])});
  constraints.push_back({{7, 0}, Relative(truth[0], truth[7])});
  const ChainedPoses chained = ChainPoses(8, constraints, truth[0]);
  EXPECT_EQ(chained.loop_closures, 1);
  EXPECT_FALSE(chained.in_tree.back());
  for (int i = 0; i < 8; ++i) EXPECT_LT(TranslationErrorM(chained.poses[i], truth[i]), 1e-9);
}

TEST(ChainPoses, ThrowsWhenAScanIsUnreached) {
  EXPECT_THROW(ChainPoses(3, {{{0, 1}, Transform::Identity()}}), InputError);
}

TEST(OptimizePoseGraph, LoopClosureSpreadsOdometryDrift) {
  const std::vector<Transform> truth = Circle();
  std::vector<PairConstraint> constraints;
  // Every odometry edge carries the same small yaw bias: the chain drifts.
  const Transform bias = Pose(0.02, 0.05, 0.0);
  for (int i = 0; i + 1 < 8; ++i) {
    constraints.push_back({{i, i + 1}, Transform(Relative(truth[i + 1], truth[i]) * bias)});
  }
  constraints.push_back({{7, 0}, Relative(truth[0], truth[7])});
  const ChainedPoses chained = ChainPoses(8, constraints, truth[0]);
  const OptimizedPoses optimised =
      OptimizePoseGraph(chained.poses, constraints, chained.in_tree, {});
  ASSERT_EQ(optimised.poses.size(), 8u);
  double chained_error = 0.0, optimised_error = 0.0;
  for (int i = 0; i < 8; ++i) {
    chained_error += TranslationErrorM(chained.poses[i], truth[i]);
    optimised_error += TranslationErrorM(optimised.poses[i], truth[i]);
  }
  EXPECT_LT(optimised_error, 0.5 * chained_error);
  EXPECT_LT(TranslationErrorM(optimised.poses[0], truth[0]), 1e-6);  // scan 0 is the reference
  EXPECT_TRUE(optimised.kept.back());
}

TEST(PairInformation, GrowsWithOverlap) {
  const Points world = MakeSyntheticStreet(3, 10.0);
  const Points scan = SimulateScan(world, Pose(0, 0, 0), 20.0, 0.0, 1);
  const InformationMatrix info = PairInformation(scan, scan, Transform::Identity(), 0.3);
  EXPECT_NEAR(info(5, 5), static_cast<double>(scan.size()), 1.0);  // one term per correspondence
  const InformationMatrix none = PairInformation(scan, scan, Pose(0, 100, 0), 0.3);
  EXPECT_LT(none(5, 5), 1.0);
}

}  // namespace
}  // namespace boicp
