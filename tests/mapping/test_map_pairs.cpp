// Pairing policies and seeds (core/map_pairs): the daemon's plan of work.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/mapping/batch_pairing.hpp"
#include "boicp/mapping/drives.hpp"
#include "boicp/mapping/map_pairs.hpp"
#include "boicp/mapping/map_up.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MapPairs, ConsecutivePairsRunSourceIOntoTargetINext) {
  EXPECT_THAT(ConsecutivePairs(4), ElementsAre(PairIndex{0, 1}, PairIndex{1, 2}, PairIndex{2, 3}));
  EXPECT_TRUE(ConsecutivePairs(1).empty());
}

TEST(MapPairs, ValidatePairsNamesTheProblem) {
  EXPECT_THAT(ErrorOf([] { ValidatePairs(3, {{0, 3}}, false); }), HasSubstr("out of range"));
  EXPECT_THAT(ErrorOf([] { ValidatePairs(3, {{1, 1}}, false); }), HasSubstr("itself"));
  EXPECT_THAT(ErrorOf([] {
                ValidatePairs(3, {{0, 1}, {1, 0}}, false);
              }),
              HasSubstr("already paired"));
  EXPECT_THAT(ErrorOf([] {
                ValidatePairs(4, {{0, 1}, {2, 3}}, true);
              }),
              HasSubstr("do not connect scan 2"));
  EXPECT_EQ(ErrorOf([] { ValidatePairs(4, {{0, 1}, {2, 3}}, false); }), "");
  EXPECT_EQ(ErrorOf([] { ValidatePairs(4, {{1, 0}, {2, 1}, {3, 0}}, true); }), "");
}

// One request, one plan, whichever front end asked: the same checks and the
// same extra pairs for the daemon and `boicp map`.
TEST(MapPairs, APairingRequestPlansEveryModeWithItsExtraPairs) {
  std::vector<ScanSource> scans(4);
  for (ScanSource& scan : scans) scan.load.format = CloudFormat::kPcd;
  PairingRequest consecutive;
  consecutive.pairs = {{3, 0}};
  const PairingPlan chained = PlanPairing(consecutive, scans, std::nullopt);
  EXPECT_FALSE(chained.keyframes);
  EXPECT_EQ(chained.chain, ConsecutivePairs(4));
  EXPECT_THAT(chained.extras, ElementsAre(PairIndex{3, 0}));

  PairingRequest overlap;
  overlap.mode = PairingMode::kOverlap;
  overlap.pairs = {{3, 1}};
  const PairingPlan keyframes = PlanPairing(overlap, scans, std::nullopt);
  EXPECT_TRUE(keyframes.keyframes);
  EXPECT_DOUBLE_EQ(keyframes.overlap_threshold, 0.7);
  EXPECT_THAT(keyframes.extras, ElementsAre(PairIndex{3, 1}));
  overlap.overlap_threshold = 0.45;
  EXPECT_DOUBLE_EQ(PlanPairing(overlap, scans, std::nullopt).overlap_threshold, 0.45);

  PairingRequest listed;
  listed.mode = PairingMode::kExplicit;
  listed.pairs = {{1, 0}, {2, 1}, {3, 2}, {3, 0}};
  const PairingPlan fixed = PlanPairing(listed, scans, std::nullopt);
  EXPECT_EQ(fixed.chain, listed.pairs);
  EXPECT_TRUE(fixed.extras.empty());
}

TEST(MapPairs, APairingRequestNamesWhatIsWrongAndWhereThePairsCameFrom) {
  const std::vector<ScanSource> scans(3);
  PairingRequest repeated;
  repeated.pairs = {{1, 0}};  // consecutive already pairs 0 and 1
  EXPECT_THAT(ErrorOf([&] { PlanPairing(repeated, scans, std::nullopt); }),
              HasSubstr("pairing.pairs: pair 2 (1->0): the same two scans are already paired"));
  PairingRequest threshold;
  threshold.mode = PairingMode::kOverlap;
  threshold.overlap_threshold = 1.5;
  EXPECT_THAT(ErrorOf([&] { PlanPairing(threshold, scans, std::nullopt); }),
              HasSubstr("pairing.overlap_threshold must be in (0, 1]"));
  PairingRequest unconnected;
  unconnected.mode = PairingMode::kExplicit;
  unconnected.pairs = {{0, 1}};
  EXPECT_THAT(ErrorOf([&] { PlanPairing(unconnected, scans, std::nullopt, "pairs.txt"); }),
              HasSubstr("pairs.txt: the pairs do not connect scan 2"));
  unconnected.pairs.clear();
  EXPECT_THAT(ErrorOf([&] { PlanPairing(unconnected, scans, std::nullopt); }),
              HasSubstr("explicit pairing needs pairs"));
  // Overlap pairing connects its scans itself; its extra pairs need not.
  PairingRequest loose;
  loose.mode = PairingMode::kOverlap;
  loose.pairs = {{2, 0}};
  EXPECT_EQ(ErrorOf([&] { PlanPairing(loose, scans, std::nullopt); }), "");
}

TEST(MapPairs, PairingModesHaveOneNameEach) {
  for (const PairingMode mode :
       {PairingMode::kConsecutive, PairingMode::kOverlap, PairingMode::kExplicit}) {
    EXPECT_EQ(PairingModeFromName(PairingModeName(mode)), mode);
  }
  EXPECT_EQ(PairingModeFromName("keyframes"), std::nullopt);
}

TEST(MapPairs, PairSeedDependsOnJobSeedAndPairOnly) {
  EXPECT_EQ(PairSeed(5, {1, 2}), PairSeed(5, {1, 2}));
  EXPECT_NE(PairSeed(5, {1, 2}), PairSeed(5, {2, 1}));
  EXPECT_NE(PairSeed(5, {1, 2}), PairSeed(6, {1, 2}));
}

TEST(MapPairs, DefaultOverlapThresholdsAreThePapers) {
  EXPECT_DOUBLE_EQ(DefaultOverlapThreshold(SensorKind::kLidar), 0.7);
  EXPECT_DOUBLE_EQ(DefaultOverlapThreshold(SensorKind::kDepthCamera), 0.6);
}

// The format stands in for the sensor only until --sensor sets it.
TEST(MapPairs, ASetSensorDecidesTheOverlapAndTheUpInsteadOfTheFormat) {
  std::vector<ScanSource> depth_images(2), point_files(2);
  for (ScanSource& scan : depth_images) scan.load.format = CloudFormat::kDepthPng;
  for (ScanSource& scan : point_files) scan.load.format = CloudFormat::kPcd;
  EXPECT_DOUBLE_EQ(BatchOverlapThreshold(depth_images, std::nullopt), 0.6);
  EXPECT_DOUBLE_EQ(BatchOverlapThreshold(point_files, std::nullopt), 0.7);
  EXPECT_DOUBLE_EQ(BatchOverlapThreshold(point_files, SensorKind::kDepthCamera), 0.6);
  EXPECT_DOUBLE_EQ(BatchOverlapThreshold(depth_images, SensorKind::kLidar), 0.7);

  EXPECT_EQ(SensorUp(std::nullopt, CloudFormat::kPcd), std::nullopt);
  EXPECT_EQ(SensorUp(std::nullopt, CloudFormat::kKittiBin), Eigen::Vector3d::UnitZ());
  EXPECT_EQ(SensorUp(std::nullopt, CloudFormat::kDepthPng), Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(SensorUp(SensorKind::kLidar, CloudFormat::kPcd), Eigen::Vector3d::UnitZ());
  EXPECT_EQ(SensorUp(SensorKind::kDepthCamera, CloudFormat::kPcd), Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(SensorUp(SensorKind::kOther, CloudFormat::kKittiBin), std::nullopt);
}

using ProbeOutcome = KeyframePlanner::ProbeOutcome;

// Feeds the planner probe outcomes from a table until it is done.
std::vector<PairIndex> RunPlanner(int scans, double threshold,
                                  const std::function<ProbeOutcome(PairIndex)>& outcome,
                                  int window) {
  KeyframePlanner planner(scans, threshold);
  for (int guard = 0; guard < 1000 && !planner.Done(); ++guard) {
    const auto probes = planner.NextProbes(window);
    if (probes.empty()) ADD_FAILURE() << "planner stalled";
    for (const PairIndex& p : probes) planner.Record(p, outcome(p));
  }
  return planner.ChainPairs();
}

// Outcomes with this overlap, well inside the search box and not doubtful.
std::function<ProbeOutcome(PairIndex)> Overlaps(const std::function<double(PairIndex)>& overlap) {
  return [overlap](PairIndex p) { return ProbeOutcome{overlap(p), 0.0, false}; };
}

TEST(KeyframePlanner, NewKeyframeWhenOverlapDropsBelowThreshold) {
  // Overlap falls by 0.15 per scan of distance: scans 1 and 2 see keyframe 0
  // well enough (0.85, 0.7), scan 3 does not (0.55), so 2 becomes the keyframe.
  const auto overlap = [](PairIndex p) { return 1.0 - 0.15 * std::abs(p.source - p.target); };
  EXPECT_THAT(RunPlanner(6, 0.7, Overlaps(overlap), 1),
              ElementsAre(PairIndex{1, 0}, PairIndex{2, 0}, PairIndex{3, 2}, PairIndex{4, 2},
                          PairIndex{5, 4}));
}

TEST(KeyframePlanner, SameChainWhateverTheWindow) {
  const auto overlap = [](PairIndex p) { return 1.0 - 0.1 * std::abs(p.source - p.target); };
  const auto one = RunPlanner(9, 0.75, Overlaps(overlap), 1);
  EXPECT_EQ(RunPlanner(9, 0.75, Overlaps(overlap), 4), one);
  EXPECT_EQ(RunPlanner(9, 0.75, Overlaps(overlap), 16), one);
  EXPECT_EQ(one.size(), 8u);
}

// A drive whose scans overlap well at any distance (a long straight street),
// while each step takes 0.3 of the search box: scan 2 hangs off keyframe 0
// at 0.6 of the box, past half, so scan 3, which may lie outside keyframe
// 0's box, is registered onto scan 2 instead.
TEST(KeyframePlanner, AScanPastHalfTheSearchBoxBecomesTheKeyframe) {
  const auto outcome = [](PairIndex p) {
    return ProbeOutcome{0.9, 0.3 * std::abs(p.source - p.target), false};
  };
  const auto one = RunPlanner(6, 0.7, outcome, 1);
  EXPECT_THAT(one, ElementsAre(PairIndex{1, 0}, PairIndex{2, 0}, PairIndex{3, 2}, PairIndex{4, 2},
                               PairIndex{5, 4}));
  EXPECT_EQ(RunPlanner(6, 0.7, outcome, 4), one);
}

TEST(KeyframePlanner, ADoubtfulProbeCountsAsTooLittleOverlap) {
  const auto outcome = [](PairIndex p) { return ProbeOutcome{0.9, 0.0, p == PairIndex{3, 0}}; };
  EXPECT_THAT(RunPlanner(6, 0.7, outcome, 2),
              ElementsAre(PairIndex{1, 0}, PairIndex{2, 0}, PairIndex{3, 2}, PairIndex{4, 2},
                          PairIndex{5, 2}));
}

TEST(KeyframePlanner, AdjacentScanIsKeptEvenWithLowOverlap) {
  EXPECT_THAT(RunPlanner(3, 0.7, Overlaps([](PairIndex) { return 0.1; }), 2),
              ElementsAre(PairIndex{1, 0}, PairIndex{2, 1}));
}

TEST(KeyframePlanner, RejectsBadArguments) {
  EXPECT_THROW(KeyframePlanner(0, 0.7), InputError);
  EXPECT_THROW(KeyframePlanner(3, 0.0), InputError);
  EXPECT_THROW(KeyframePlanner(3, 1.5), InputError);
}

TEST(Drives, EachScanBelongsToTheDriveThatStartsAtOrBeforeIt) {
  EXPECT_EQ(DriveOf({}, 7), 0);
  EXPECT_EQ(DriveOf({3, 5}, 2), 0);
  EXPECT_EQ(DriveOf({3, 5}, 3), 1);
  EXPECT_EQ(DriveOf({3, 5}, 6), 2);
}

TEST(Drives, ConsecutivePairsStayWithinADrive) {
  const std::vector<PairIndex> pairs = ConsecutivePairsOfDrives(6, {3});
  ASSERT_EQ(pairs.size(), 4u);
  EXPECT_EQ(pairs[1], (PairIndex{1, 2}));
  EXPECT_EQ(pairs[2], (PairIndex{3, 4}));
  EXPECT_EQ(ConsecutivePairsOfDrives(6, {}), ConsecutivePairs(6));
}

TEST(Drives, ADriveOfOneScanIsNamed) {
  EXPECT_NO_THROW(ValidateDriveStarts(6, {2, 4}));
  try {
    ValidateDriveStarts(5, {2, 4}, {"a", "b", "c"});
    FAIL() << "drive c has one scan";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("c: a drive needs at least 2 scans, it has 1"));
  }
  EXPECT_THROW(ValidateDriveStarts(6, {3, 2}), InputError) << "not ascending";
}

TEST(Drives, DrivesApartFromTheFirstAreListed) {
  const std::vector<PairIndex> chains = ConsecutivePairsOfDrives(9, {3, 6});
  EXPECT_EQ(DrivesApartFromTheFirst(9, {3, 6}, chains), std::vector<int>({1, 2}));
  std::vector<PairIndex> joined = chains;
  joined.push_back({7, 4});  // the third drive joins the second, not the first
  EXPECT_EQ(DrivesApartFromTheFirst(9, {3, 6}, joined), std::vector<int>({1, 2}));
  joined.push_back({5, 0});
  EXPECT_EQ(DrivesApartFromTheFirst(9, {3, 6}, joined), std::vector<int>());
}

TEST(Drives, SeveralDrivesArePlannedAsChainsOfConsecutivePairs) {
  std::vector<ScanSource> scans(5);
  PairingRequest request;
  request.drive_starts = {2};
  const PairingPlan plan = PlanPairing(request, scans, std::nullopt);
  EXPECT_EQ(plan.chain, std::vector<PairIndex>({{0, 1}, {2, 3}, {3, 4}}));
  request.mode = PairingMode::kOverlap;
  EXPECT_THROW(PlanPairing(request, scans, std::nullopt), InputError);
}

}  // namespace
}  // namespace boicp
