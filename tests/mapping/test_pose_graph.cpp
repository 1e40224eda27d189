// Pose chaining and pose-graph optimisation (core/pose_graph).

#include <random>

#include <gtest/gtest.h>

#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/chain_uncertainty.hpp"
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

TEST(ChainPoses, PlacesAScanByItsMostConfidentDoubtfulPair) {
  const std::vector<Transform> truth = {Pose(0, 0, 0), Pose(0.2, 2, 0), Pose(0.4, 4, 1)};
  const Transform wrong = Pose(1.0, 5, 5);
  // Scan 2 hangs on two doubtful pairs; the less confident one is listed first.
  const std::vector<PairConstraint> constraints = {
      {{0, 1}, Relative(truth[1], truth[0])},
      {{1, 2}, wrong, InformationMatrix::Identity(), 0.2},
      {{0, 2}, Relative(truth[2], truth[0]), InformationMatrix::Identity(), 0.6},
  };
  const ChainedPoses chained = ChainPoses(3, constraints);
  EXPECT_FALSE(chained.in_tree[1]);
  EXPECT_TRUE(chained.in_tree[2]);
  EXPECT_LT(TranslationErrorM(chained.poses[2], truth[2]), 1e-9);
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
// information is shaped like PlaneInformation's: rotation weighs the square
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

// ---- Calibrated information: loops on a drifted chain ---------------------

// A drive `laps` times around a circle of radius 5 m, `per_lap` scans a lap.
std::vector<Transform> Laps(int laps, int per_lap) {
  std::vector<Transform> poses;
  for (int i = 0; i < laps * per_lap; ++i) {
    const double a = 2.0 * M_PI * i / per_lap;
    poses.push_back(Pose(a + M_PI / 2, 5 * std::cos(a), 5 * std::sin(a)));
  }
  return poses;
}

// Information shaped as PlaneInformation gives it: 5000 inliers spread 2 m
// about the target's origin.
InformationMatrix FiveThousandInliers() {
  InformationMatrix information = InformationMatrix::Identity() * 5000.0;
  information.topLeftCorner<3, 3>() *= 4.0;
  return information;
}

// The odometry chain of `truth`, each step off by a small yaw and forward bias.
std::vector<PairConstraint> DriftingChain(const std::vector<Transform>& truth) {
  std::vector<PairConstraint> chain;
  const Transform bias = Pose(0.003, 0.005, 0.0);
  for (size_t i = 0; i + 1 < truth.size(); ++i) {
    chain.push_back({{static_cast<int>(i), static_cast<int>(i + 1)},
                     Transform(Relative(truth[i + 1], truth[i]) * bias),
                     FiveThousandInliers()});
  }
  return chain;
}

// Root-mean-square translation error over the poses, metres (scan 0 is fixed
// in both, so no alignment is needed).
double RmsTranslationError(const std::vector<Transform>& poses,
                           const std::vector<Transform>& truth) {
  double sum = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    sum += std::pow(TranslationErrorM(poses[i], truth[i]), 2);
  }
  return std::sqrt(sum / static_cast<double>(poses.size()));
}

PoseGraphOptions CalibratedOptions() {
  PoseGraphOptions options;
  options.max_correspondence_distance = 0.05;
  options.pair_error = 0.015;
  return options;
}

TEST(CalibratedInformation, IsTheMeanInlierInformationOverTheErrorSquared) {
  const InformationMatrix calibrated = CalibratedInformation(FiveThousandInliers(), 0.01);
  EXPECT_NEAR(calibrated(3, 3), 1e4, 1e4 * 2 * kMinEdgeWeight);  // 1 / (1 cm)^2 along each axis
  EXPECT_NEAR(calibrated(0, 0), 4e4, 1e4 * 2 * kMinEdgeWeight);  // the inliers' spread stays
  EXPECT_NEAR(calibrated(0, 3), 0.0, 1e-9);
  // A wall: every inlier faces x, so y and z are free but for the floor.
  InformationMatrix wall = InformationMatrix::Zero();
  wall(3, 3) = 3000.0;
  const InformationMatrix along_wall = CalibratedInformation(wall, 0.01);
  EXPECT_NEAR(along_wall(3, 3), 3e4, 20.0);
  EXPECT_NEAR(along_wall(4, 4), kMinEdgeWeight * 1e4, 1e-9);
  EXPECT_NEAR(CalibratedInformation(InformationMatrix::Zero(), 0.01)(0, 0), kMinEdgeWeight * 1e4,
              1e-9);
}

TEST(ChainUncertainty, GrowsAlongTheChainAndIsSymmetric) {
  const std::vector<Transform> truth = Laps(1, 40);
  std::vector<PairConstraint> chain = DriftingChain(truth);
  for (PairConstraint& c : chain) {
    c.T_target_source = Relative(truth[static_cast<size_t>(c.pair.target)],
                                 truth[static_cast<size_t>(c.pair.source)]);
    c.information = CalibratedInformation(c.information, 0.01);
  }
  const ChainedPoses chained = ChainPoses(40, chain);
  const ChainUncertainty uncertainty(chained.poses, chain, chained.in_tree);
  const auto translation_variance = [&](int a, int b) {
    return uncertainty.Between(a, b).bottomRightCorner(3, 3).trace();
  };
  double previous = 0.0;
  for (int k = 1; k < 40; k += 6) {
    EXPECT_GT(translation_variance(0, k), previous) << k;
    previous = translation_variance(0, k);
  }
  // The edge's own measurement, T_1_0: its translation variance, 3 x (1 cm)^2.
  EXPECT_NEAR(translation_variance(1, 0), 3e-4, 1e-6);
  // Walking the other way round gives about the same uncertainty.
  EXPECT_NEAR(translation_variance(5, 20), translation_variance(20, 5),
              0.2 * translation_variance(5, 20));
}

TEST(OptimizePoseGraph, CalibratedInformationKeepsARightLoopOnADriftedChain) {
  const std::vector<Transform> truth = Laps(1, 40);
  std::vector<PairConstraint> constraints = DriftingChain(truth);
  constraints.push_back({{39, 0}, Relative(truth[0], truth[39]), FiveThousandInliers()});
  const ChainedPoses chained = ChainPoses(40, constraints, truth[0]);
  const double drift = MaxTranslationError(chained.poses, truth);
  ASSERT_GT(drift, 0.2);  // the chain's end is off by more than its pairs' errors add up to

  // Information counting every inlier as independent makes the drift look
  // like an outlier: the loop is pruned and nothing improves.
  PoseGraphOptions per_inlier = CalibratedOptions();
  per_inlier.pair_error = 0.0;
  const OptimizedPoses pruned =
      OptimizePoseGraph(chained.poses, constraints, chained.in_tree, per_inlier);
  EXPECT_FALSE(pruned.kept.back());

  const OptimizedPoses kept =
      OptimizePoseGraph(chained.poses, constraints, chained.in_tree, CalibratedOptions());
  EXPECT_TRUE(kept.kept.back()) << kept.left_out_because.back();
  EXPECT_TRUE(kept.left_out_because.back().empty());
  EXPECT_LT(RmsTranslationError(kept.poses, truth),
            0.3 * RmsTranslationError(chained.poses, truth));
}

TEST(OptimizePoseGraph, CalibratedInformationLeavesOutAWrongTrustedLoop) {
  const std::vector<Transform> truth = Laps(1, 40);
  std::vector<PairConstraint> constraints = DriftingChain(truth);
  // A right loop, and a wrong one: 20 -> 5 put 2 m and 40 degrees off.
  constraints.push_back({{39, 0}, Relative(truth[0], truth[39]), FiveThousandInliers()});
  constraints.push_back({{20, 5},
                         Transform(Relative(truth[5], truth[20]) * Pose(0.7, 2.0, 0.0)),
                         FiveThousandInliers()});
  const ChainedPoses chained = ChainPoses(40, constraints, truth[0]);
  const OptimizedPoses optimised =
      OptimizePoseGraph(chained.poses, constraints, chained.in_tree, CalibratedOptions());
  EXPECT_TRUE(optimised.kept[constraints.size() - 2]);
  EXPECT_FALSE(optimised.kept.back());
  EXPECT_NE(optimised.left_out_because.back().find("disagrees"), std::string::npos)
      << optimised.left_out_because.back();
}

TEST(OptimizePoseGraph, TwentyPercentWrongTrustedLoopsAtMostDoubleTheError) {
  // Two laps: each scan of the second passes its twin of the first.
  const std::vector<Transform> truth = Laps(2, 40);
  const std::vector<PairConstraint> chain = DriftingChain(truth);
  std::vector<PairConstraint> right = chain;
  for (int k = 2; k < 40; k += 5) {  // 8 right loops
    right.push_back({{k + 40, k},
                     Relative(truth[static_cast<size_t>(k)], truth[static_cast<size_t>(k + 40)]),
                     FiveThousandInliers()});
  }
  const auto rms_after = [&](const std::vector<PairConstraint>& constraints) {
    const ChainedPoses chained = ChainPoses(80, constraints, truth[0]);
    const OptimizedPoses optimised =
        OptimizePoseGraph(chained.poses, constraints, chained.in_tree, CalibratedOptions());
    return RmsTranslationError(optimised.poses, truth);
  };
  const double clean = rms_after(right);
  EXPECT_LT(clean, 0.5 * rms_after(chain));

  // 2 wrong loops among 10 (20 %), trusted like the right ones, drawn at
  // random: between unrelated scans or the right ones, 0.3 to 3 m and up to
  // 60 degrees off.
  std::mt19937 rng(20261207);
  std::uniform_int_distribution<int> scan(0, 79);
  std::uniform_real_distribution<double> offset(0.3, 3.0), yaw(-1.05, 1.05);
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<PairConstraint> noisy = right;
    for (int wrong = 0; wrong < 2; ++wrong) {
      int a = scan(rng), b = scan(rng);
      while (std::abs(a - b) < 10) b = scan(rng);
      const Transform off = Pose(yaw(rng), offset(rng), offset(rng) - 1.5);
      noisy.push_back({{std::max(a, b), std::min(a, b)},
                       Transform(Relative(truth[static_cast<size_t>(std::min(a, b))],
                                          truth[static_cast<size_t>(std::max(a, b))]) *
                                 off),
                       FiveThousandInliers()});
    }
    EXPECT_LT(rms_after(noisy), 2.0 * clean) << "trial " << trial;
  }
}

}  // namespace
}  // namespace boicp
