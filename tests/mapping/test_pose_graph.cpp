// Pose chaining and pose-graph optimisation (core/pose_graph).

#include <random>

#include <gtest/gtest.h>

#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/pose_graph.hpp"
#include "evaluation.hpp"

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

// Largest translation error over the poses, metres.
double MaxTranslationError(const std::vector<Transform>& poses,
                           const std::vector<Transform>& truth) {
  double worst = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    worst = std::max(worst, TranslationErrorM(poses[i], truth[i]));
  }
  return worst;
}

// The circle's odometry chain 0->1->...->7 plus the loop closure 7->0. The
// information is shaped like PairInformation's: rotation weighs the square
// of the points' spread (here 10 m) times the translation's.
std::vector<PairConstraint> CircleWithLoop(const std::vector<Transform>& truth) {
  InformationMatrix information = InformationMatrix::Identity();
  information.topLeftCorner<3, 3>() *= 100.0;
  std::vector<PairConstraint> constraints;
  for (int i = 0; i + 1 < 8; ++i)
    constraints.push_back({{i, i + 1}, Relative(truth[i + 1], truth[i]), information});
  constraints.push_back({{7, 0}, Relative(truth[0], truth[7]), information});
  return constraints;
}

TEST(ChainPoses, PrefersATrustedAlternativeToADoubtfulEdge) {
  const std::vector<Transform> truth = {Pose(0, 0, 0), Pose(0, 2, 0), Pose(0, 4, 0), Pose(0, 6, 0)};
  std::vector<PairConstraint> constraints = {
      {{0, 1}, Relative(truth[1], truth[0])},
      // Listed first but wrong by 2 m, and marked doubtful.
      {{1, 2},
       Transform(Relative(truth[2], truth[1]) * Pose(0, 2, 0)),
       InformationMatrix::Identity(),
       0.1},
      {{2, 3}, Relative(truth[3], truth[2])},
      {{0, 2}, Relative(truth[2], truth[0])},  // a trusted skip over the doubtful pair
  };
  const ChainedPoses chained = ChainPoses(4, constraints);
  EXPECT_FALSE(chained.in_tree[1]);
  EXPECT_TRUE(chained.in_tree[3]);
  EXPECT_EQ(chained.loop_closures, 1);
  EXPECT_LT(MaxTranslationError(chained.poses, truth), 1e-9);
}

TEST(ChainPoses, ChainsADoubtfulEdgeWhenNothingElseConnects) {
  const std::vector<Transform> truth = {Pose(0, 0, 0), Pose(0, 2, 0)};
  const ChainedPoses chained =
      ChainPoses(2, {{{0, 1}, Relative(truth[1], truth[0]), InformationMatrix::Identity(), 0.0}});
  EXPECT_TRUE(chained.in_tree[0]);
  EXPECT_LT(MaxTranslationError(chained.poses, truth), 1e-9);
}

TEST(OptimizePoseGraph, LowConfidenceWrongEdgeIsOutvotedByTheLoop) {
  const std::vector<Transform> truth = Circle();
  std::vector<PairConstraint> constraints = CircleWithLoop(truth);
  // Odometry edge 3->4 is wrong.
  constraints[3].T_target_source = Transform(constraints[3].T_target_source * Pose(0.02, 0.3, 0));
  PoseGraphOptions options;
  options.max_correspondence_distance = 2.0;  // no edge is pruned in any of the runs

  auto optimise = [&](double wrong_confidence, double loop_confidence) {
    std::vector<PairConstraint> weighted = constraints;
    weighted[3].confidence = wrong_confidence;
    weighted.back().confidence = loop_confidence;
    const ChainedPoses chained = ChainPoses(8, weighted, truth[0]);
    const OptimizedPoses optimised =
        OptimizePoseGraph(chained.poses, weighted, chained.in_tree, options);
    for (size_t e = 0; e < weighted.size(); ++e) EXPECT_TRUE(optimised.kept[e]) << e;
    return MaxTranslationError(optimised.poses, truth);
  };
  const double trusted = optimise(1.0, 1.0);  // the error spreads over every edge
  EXPECT_GT(trusted, 0.05);
  // Most of the error goes where the doubt is: with a trusted loop closure
  // (which then chains in its place) and with a doubtful but likelier one
  // (the wrong edge stays in the tree, weighted down). In a loop of 8 the
  // other 7 edges still take 7 / (7 + 1 / 0.01) of it.
  EXPECT_LT(optimise(0.01, 1.0), 0.3 * trusted);
  EXPECT_LT(optimise(0.01, 0.45), 0.4 * trusted);
}

TEST(OptimizePoseGraph, DoubtfulLoopClosureThatDisagreesIsPruned) {
  const std::vector<Transform> truth = Circle();
  std::vector<PairConstraint> constraints = CircleWithLoop(truth);
  // A wrong loop closure, close enough that the line process alone keeps it.
  constraints.back().T_target_source =
      Transform(constraints.back().T_target_source * Pose(0.0, 0.4, 0.0));

  const ChainedPoses chained = ChainPoses(8, constraints, truth[0]);
  const OptimizedPoses trusted = OptimizePoseGraph(chained.poses, constraints, chained.in_tree, {});
  ASSERT_TRUE(trusted.kept.back());
  EXPECT_GT(MaxTranslationError(trusted.poses, truth), 0.05);

  constraints.back().confidence = 0.2;
  const OptimizedPoses doubtful =
      OptimizePoseGraph(chained.poses, constraints, chained.in_tree, {});
  EXPECT_FALSE(doubtful.kept.back());
  EXPECT_LT(MaxTranslationError(doubtful.poses, truth), 1e-6);
}

TEST(OptimizePoseGraph, DoubtfulLoopClosureThatAgreesIsKept) {
  const std::vector<Transform> truth = Circle();
  std::vector<PairConstraint> constraints = CircleWithLoop(truth);
  constraints.back().confidence = 0.2;
  const ChainedPoses chained = ChainPoses(8, constraints, truth[0]);
  const OptimizedPoses optimised =
      OptimizePoseGraph(chained.poses, constraints, chained.in_tree, {});
  EXPECT_TRUE(optimised.kept.back());
  EXPECT_GT(optimised.line_process.back(), 0.9);
  EXPECT_LT(MaxTranslationError(optimised.poses, truth), 1e-6);
}

}  // namespace
}  // namespace boicp
