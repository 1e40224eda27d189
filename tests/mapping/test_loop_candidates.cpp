// Loop-closure candidates on chained poses (core/mapping/loop_candidates).

#include <algorithm>
#include <map>

#include <gtest/gtest.h>

#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/loop_candidates.hpp"
#include "evaluation.hpp"

namespace boicp {
namespace {

// A drive once around a 20 m square, one scan a metre, ending where it began.
std::vector<Transform> SquareDrive() {
  std::vector<Transform> poses;
  for (int side = 0; side < 4; ++side) {
    for (int step = 0; step < 20; ++step) {
      const double yaw = side * M_PI / 2;
      const Eigen::Vector3d corner[4] = {{0, 0, 0}, {20, 0, 0}, {20, 20, 0}, {0, 20, 0}};
      poses.push_back(PoseFromYawTranslation(
          yaw, corner[side] + step * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0)));
    }
  }
  poses.push_back(poses.front());
  return poses;
}

std::vector<Point> Positions(const std::vector<Transform>& poses) {
  std::vector<Point> positions;
  for (const Transform& pose : poses) positions.push_back(pose.topRightCorner<3, 1>());
  return positions;
}

TEST(LoopCandidates, FindsTheReturnToTheStartAndNothingAlongTheWay) {
  const std::vector<Transform> poses = SquareDrive();
  LoopCandidateOptions options;
  options.reach = 2.0;
  options.drift_per_metre = 0.0;
  const std::vector<LoopCandidate> candidates =
      LoopCandidatesFromPoses(poses, Positions(poses), options);
  ASSERT_FALSE(candidates.empty());
  for (const LoopCandidate& c : candidates) {
    // Only the stretch near the start and end comes back within reach.
    EXPECT_GE(c.pair.source, 78) << PairName(c.pair);
    EXPECT_LE(c.pair.target, 2) << PairName(c.pair);
    EXPECT_LE(c.distance, c.reach);
    // The prior is the chain's relative pose.
    EXPECT_TRUE(c.prior.isApprox(poses[static_cast<size_t>(c.pair.target)].inverse() *
                                     poses[static_cast<size_t>(c.pair.source)],
                                 1e-9));
  }
  // The best one, the exact return, is kept.
  EXPECT_TRUE(std::any_of(candidates.begin(), candidates.end(), [](const LoopCandidate& c) {
    return c.pair == PairIndex{80, 0};
  }));
}

TEST(LoopCandidates, KeepsTheCapAndTheSpacing) {
  const std::vector<Transform> poses = SquareDrive();
  LoopCandidateOptions options;
  options.reach = 6.0;
  options.max_per_scan = 1;
  options.min_spacing = 3;
  const std::vector<LoopCandidate> candidates =
      LoopCandidatesFromPoses(poses, Positions(poses), options);
  ASSERT_GE(candidates.size(), 2u);
  std::map<int, int> per_scan;
  for (size_t a = 0; a < candidates.size(); ++a) {
    EXPECT_LE(++per_scan[candidates[a].pair.source], 1);
    EXPECT_GE(candidates[a].pair.source - candidates[a].pair.target, options.min_sequence_gap);
    for (size_t b = a + 1; b < candidates.size(); ++b) {
      const bool close_at_both_ends =
          std::abs(candidates[a].pair.source - candidates[b].pair.source) < 3 &&
          std::abs(candidates[a].pair.target - candidates[b].pair.target) < 3;
      EXPECT_FALSE(close_at_both_ends)
          << PairName(candidates[a].pair) << " " << PairName(candidates[b].pair);
    }
  }
}

TEST(LoopCandidates, ReachGrowsWithThePathDriven) {
  // Out along a street and back in the other lane, 3 m over: only drift
  // since the start can bring the lanes within reach.
  std::vector<Transform> poses;
  for (int k = 0; k < 50; ++k) poses.push_back(PoseFromYawTranslation(0.0, {k * 1.0, 0.0, 0.0}));
  for (int k = 49; k >= 0; --k) poses.push_back(PoseFromYawTranslation(M_PI, {k * 1.0, 3.0, 0.0}));
  LoopCandidateOptions options;
  options.reach = 1.0;
  options.drift_per_metre = 0.0;
  EXPECT_TRUE(LoopCandidatesFromPoses(poses, Positions(poses), options).empty());
  options.drift_per_metre = 0.05;  // 1 m + 5 % of 101 m between the ends
  const std::vector<LoopCandidate> found =
      LoopCandidatesFromPoses(poses, Positions(poses), options);
  ASSERT_FALSE(found.empty());
  // The most drift is taken out at the far ends of the path.
  EXPECT_TRUE(std::any_of(found.begin(), found.end(), [](const LoopCandidate& c) {
    return c.pair == PairIndex{99, 0};
  }));
  for (const LoopCandidate& c : found) EXPECT_LE(c.distance, c.reach);
}

TEST(LoopCandidates, NamesItsModes) {
  EXPECT_EQ(LoopSearchFromName("auto", "loops"), LoopSearch::kAuto);
  EXPECT_EQ(LoopSearchFromName("off", "loops"), LoopSearch::kOff);
  EXPECT_EQ(LoopSearchName(LoopSearchFromName("off", "loops")), "off");
  try {
    LoopSearchFromName("sometimes", "loops");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("loops"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace boicp
