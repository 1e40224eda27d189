// BO-ICP end to end on a generated street: far from identity, both modes.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "boicp/icp/icp.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "boicp/registration/refinement.hpp"
#include "boicp/registration/scan_features.hpp"
#include "evaluation.hpp"

namespace boicp {
namespace {

struct StreetPair {
  Points source, target;
  Transform truth;  // T_target_source
};

StreetPair MakeStreetPair(double yaw) {
  const Points world = MakeSyntheticStreet(11, 15.0);
  const Transform T_world_target = PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8});
  const Transform T_world_source = PoseFromYawTranslation(yaw, {1.2, 0.4, 1.8});
  return {SimulateScan(world, T_world_source, 30.0, 0.01, 1),
          SimulateScan(world, T_world_target, 30.0, 0.01, 2),
          T_world_target.inverse() * T_world_source};
}

BoIcpConfig SmallConfig(SearchMode mode) {
  BoIcpConfig config = PresetConfig("A");
  config.automatic.clear();  // the preset's fixed voxel and translation box
  config.retry_when_doubtful = false;
  config.mode = mode;
  config.rotation_bounds = Eigen::Vector3d(0.2, 0.2, M_PI);  // a car: any yaw, small roll and pitch
  config.evaluation_points = 1000;
  config.seed = 5;
  config.budget = Budget::kFixed;  // the search itself, as the paper runs it
  return config;
}

class BoIcpModes : public ::testing::TestWithParam<SearchMode> {};

TEST_P(BoIcpModes, RecoversLargeYawOnSyntheticStreet) {
  const StreetPair pair = MakeStreetPair(2.3);  // 132 degrees: plain ICP from identity fails
  const RegistrationResult result = RegisterPair(pair.source, pair.target, SmallConfig(GetParam()));
  EXPECT_LT(RotationErrorDeg(result.transform, pair.truth), 1.0);
  EXPECT_LT(TranslationErrorM(result.transform, pair.truth), 0.1);
  EXPECT_GT(result.fitness, 0.5);
  EXPECT_GT(result.confidence, 0.0);
  EXPECT_LE(result.confidence, 1.0);
  EXPECT_EQ(result.evaluations, static_cast<int>(result.history.size()));
}

INSTANTIATE_TEST_SUITE_P(Modes, BoIcpModes,
                         ::testing::Values(SearchMode::kNested, SearchMode::kSixDof),
                         [](const auto& info) {
                           return SearchModeName(info.param) == "6dof" ? std::string("SixDof")
                                                                       : std::string("Nested");
                         });

// The two shortcuts of the search ICP, each on and off.
struct Shortcuts {
  size_t coarse_icp_points;
  bool join_converged_runs;
};

class BoIcpShortcuts : public ::testing::TestWithParam<Shortcuts> {};

TEST_P(BoIcpShortcuts, RecoverLargeYawAndJoinedRunsCopyAnEarlierEnd) {
  const StreetPair pair = MakeStreetPair(2.3);
  BoIcpConfig config = SmallConfig(SearchMode::kNested);
  config.coarse_icp_points = GetParam().coarse_icp_points;
  config.join_converged_runs = GetParam().join_converged_runs;
  const RegistrationResult result = RegisterPair(pair.source, pair.target, config);
  EXPECT_LT(RotationErrorDeg(result.transform, pair.truth), 1.0);
  EXPECT_LT(TranslationErrorM(result.transform, pair.truth), 0.1);

  // A joined run reports an earlier run's end bit for bit, with its score;
  // independent runs never end on exactly the same transform.
  int copies = 0;
  for (size_t i = 0; i < result.history.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (result.history[i].result != result.history[j].result) continue;
      EXPECT_EQ(result.history[i].objective, result.history[j].objective) << i << " copies " << j;
      ++copies;
      break;
    }
  }
  if (config.join_converged_runs) {
    EXPECT_GT(copies, 0);
  } else {
    EXPECT_EQ(copies, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(OnOff, BoIcpShortcuts,
                         ::testing::Values(Shortcuts{0, false}, Shortcuts{500, false},
                                           Shortcuts{0, true}, Shortcuts{500, true}),
                         [](const auto& info) {
                           return std::string(info.param.coarse_icp_points ? "Coarse" : "Single") +
                                  (info.param.join_converged_runs ? "Joining" : "Independent");
                         });

TEST(BoIcp, SameSeedSameAnswerAndThreadCountDoesNotMatter) {
  const StreetPair pair = MakeStreetPair(0.9);
  BoIcpConfig config = SmallConfig(SearchMode::kNested);
  config.iterations = 5;
  config.coarse_icp_points = 500;  // both parts of every ICP run, and joins
  const RegistrationResult a = RegisterPair(pair.source, pair.target, config);
  config.threads = 2;  // the parallel twin: the same rounds, evaluated two at a time
  const RegistrationResult b = RegisterPair(pair.source, pair.target, config);
  EXPECT_TRUE(a.transform == b.transform);
  EXPECT_EQ(a.objective, b.objective);
  ASSERT_EQ(a.history.size(), b.history.size());
  for (size_t i = 0; i < a.history.size(); ++i) {
    EXPECT_TRUE(a.history[i].initial == b.history[i].initial) << "evaluation " << i;
    EXPECT_EQ(a.history[i].objective, b.history[i].objective) << "evaluation " << i;
  }
}

// Two unrelated blobs of noise, each 10 m across.
std::pair<Points, Points> UnrelatedBlobs() {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  Points source, target;
  for (int i = 0; i < 2000; ++i) {
    source.emplace_back(u(rng), u(rng), u(rng));
    target.emplace_back(u(rng), u(rng), u(rng));
  }
  return {source, target};
}

// Two unrelated blobs of noise: no answer fits, so the first search is
// doubtful. More of its ends are compared at the finest level, and when that
// is still doubtful a second search runs in 6 DOF with another seed.
TEST(BoIcp, DoubtfulAnswerIsTriedAgainWiderThenInSixDof) {
  const auto [source, target] = UnrelatedBlobs();
  BoIcpConfig config = SmallConfig(SearchMode::kNested);
  config.iterations = 3;
  config.retry_voxel = 2.0 * config.voxel;
  config.retry_when_doubtful = true;
  const RegistrationResult result = RegisterPair(source, target, config);
  EXPECT_TRUE(result.doubtful);
  ASSERT_EQ(result.attempts.size(), 3u);
  const Attempt& first = result.attempts[0];
  const Attempt& wider = result.attempts[1];
  const Attempt& second = result.attempts[2];
  EXPECT_EQ(first.kind, AttemptKind::kSearch);
  EXPECT_EQ(first.mode, SearchMode::kNested);
  EXPECT_EQ(first.refined_ends, config.refine_candidates);
  EXPECT_EQ(wider.kind, AttemptKind::kWiderRefinement);
  EXPECT_EQ(wider.seed, first.seed);
  EXPECT_EQ(wider.evaluations, 0);
  EXPECT_GT(wider.refined_ends, first.refined_ends);
  // The wider refinement compares the first one's ends too.
  EXPECT_GE(wider.fitness, first.fitness);
  EXPECT_EQ(second.kind, AttemptKind::kSearch);
  EXPECT_EQ(second.mode, SearchMode::kSixDof);
  EXPECT_NE(second.seed, first.seed);
  int kept = 0;
  double best_fitness = 0.0;
  for (const Attempt& a : result.attempts) {
    kept += a.kept ? 1 : 0;
    best_fitness = std::max(best_fitness, a.fitness);
    if (a.kept) {
      EXPECT_EQ(a.fitness, result.fitness);
    }
  }
  EXPECT_EQ(kept, 1);
  EXPECT_EQ(result.fitness, best_fitness);

  config.retry_when_doubtful = false;
  EXPECT_EQ(RegisterPair(source, target, config).attempts.size(), 1u);
}

TEST(BoIcp, PriorIsTheFirstSample) {
  const StreetPair pair = MakeStreetPair(1.5);
  BoIcpConfig config = SmallConfig(SearchMode::kNested);
  config.random_samples = 2;
  config.iterations = 0;
  const RegistrationResult result = RegisterPair(pair.source, pair.target, config, pair.truth);
  ASSERT_FALSE(result.history.empty());
  EXPECT_TRUE(result.history.front().initial.isApprox(pair.truth, 1e-12));
  EXPECT_LT(RotationErrorDeg(result.transform, pair.truth), 1.0);
}

// The box is centred on the prior: an answer at the prior lies at its centre,
// one 2 m along x from it at half of the 4 m bound.
TEST(BoIcp, SearchReachIsTheAnswersOffsetFromTheBoxCentreOverItsBound) {
  const StreetPair pair = MakeStreetPair(1.5);
  BoIcpConfig config = SmallConfig(SearchMode::kNested);
  ASSERT_DOUBLE_EQ(config.translation_bounds.x(), 4.0);
  const RegistrationResult centred = RegisterPair(pair.source, pair.target, config, pair.truth);
  EXPECT_LT(centred.search_reach, 0.02);
  Transform shifted = pair.truth;
  shifted(0, 3) -= 2.0;
  const RegistrationResult half = RegisterPair(pair.source, pair.target, config, shifted);
  ASSERT_LT(TranslationErrorM(half.transform, pair.truth), 0.1);
  EXPECT_NEAR(half.search_reach, 0.5, 0.03);
}

TEST(BoIcp, LocalIcpHookReplacesEveryEvaluationsIcp) {
  const StreetPair pair = MakeStreetPair(0.9);
  BoIcpConfig config = SmallConfig(SearchMode::kNested);
  config.iterations = 3;
  config.coarse_icp_points = 0;                        // the hook runs every ICP in one part...
  config.join_converged_runs = false;                  // ...and to its own end
  config.icp_objective = IcpObjective::kPointToPoint;  // as the hook below
  const RegistrationResult plain = RegisterPair(pair.source, pair.target, config);

  // A hook that runs core's own ICP must reproduce the search exactly...
  int calls = 0;
  RegistrationCallbacks callbacks;
  callbacks.local_icp = [&](const Points& source, const Points& target, const Transform& initial) {
    ++calls;
    return AlignPointToPoint(source, NearestNeighborIndex(target), initial,
                             SearchIcpOptions(config))
        .transform;
  };
  const RegistrationResult hooked =
      RegisterPair(pair.source, pair.target, config, std::nullopt, callbacks);
  EXPECT_EQ(calls, plain.evaluations);
  EXPECT_TRUE(hooked.transform == plain.transform);
  EXPECT_EQ(hooked.objective, plain.objective);

  // ...and one that returns its start unchanged is what the search records.
  callbacks.local_icp = [](const Points&, const Points&, const Transform& initial) {
    return initial;
  };
  const RegistrationResult identity =
      RegisterPair(pair.source, pair.target, config, std::nullopt, callbacks);
  for (const Evaluation& e : identity.history) EXPECT_TRUE(e.result == e.initial);
}

TEST(BoIcp, FixedBudgetIsAnsweredByTheFullSearch) {
  const StreetPair pair = MakeStreetPair(2.3);
  const RegistrationResult result =
      RegisterPair(pair.source, pair.target, SmallConfig(SearchMode::kNested));
  EXPECT_EQ(result.answered_by, Rung::kFullSearch);
  ASSERT_EQ(result.attempts.size(), 1u);
  EXPECT_EQ(result.attempts[0].kind, AttemptKind::kSearch);
  EXPECT_EQ(result.evaluations, SmallConfig(SearchMode::kNested).random_samples * 2 +
                                    SmallConfig(SearchMode::kNested).iterations * 2);
}

BoIcpConfig LadderConfig() {
  BoIcpConfig config = SmallConfig(SearchMode::kNested);
  config.budget = Budget::kAuto;
  return config;
}

// Every rung's ICP runs are counted, exactly one attempt is kept, and the
// result's confidence is its, capped further when the answer is free along
// some direction.
void ExpectConsistentLadder(const RegistrationResult& result) {
  int evaluations = 0, kept = 0;
  double kept_confidence = 0.0;
  for (const Attempt& a : result.attempts) {
    evaluations += a.evaluations;
    kept += a.kept ? 1 : 0;
    if (a.kept) kept_confidence = a.confidence;
  }
  EXPECT_LE(result.confidence, kept_confidence);
  if (result.features.constrained_share >= kUnconstrainedShare) {
    EXPECT_EQ(result.confidence, kept_confidence);
  }
  EXPECT_EQ(result.evaluations, evaluations);
  EXPECT_EQ(kept, 1);
}

// A street turned by 132 degrees is beyond ICP from identity; the feature
// rung finds it with a few ICP runs where the search spends a hundred.
TEST(BoIcpLadder, FeaturesAnswerALargeTurnWithoutASearch) {
  const StreetPair pair = MakeStreetPair(2.3);
  const RegistrationResult result = RegisterPair(pair.source, pair.target, LadderConfig());
  EXPECT_LT(RotationErrorDeg(result.transform, pair.truth), 1.0);
  EXPECT_LT(TranslationErrorM(result.transform, pair.truth), 0.1);
  EXPECT_FALSE(result.doubtful);
  EXPECT_EQ(result.answered_by, Rung::kFeatures);
  ASSERT_EQ(result.attempts.size(), 1u);
  EXPECT_EQ(result.attempts[0].kind, AttemptKind::kFeatures);
  EXPECT_LT(result.evaluations, 10);
  ExpectConsistentLadder(result);
}

// A guess inside the basin (a drive's consecutive scans from identity) is
// answered by the prior rung, and a guess does not move the search box.
TEST(BoIcpLadder, AGoodGuessIsAnsweredByThePriorRung) {
  const StreetPair pair = MakeStreetPair(0.05);
  const RegistrationResult result = RegisterPair(pair.source, pair.target, LadderConfig(),
                                                 std::nullopt, {}, Transform::Identity());
  EXPECT_EQ(result.answered_by, Rung::kPrior);
  EXPECT_LT(RotationErrorDeg(result.transform, pair.truth), 1.0);
  EXPECT_LT(TranslationErrorM(result.transform, pair.truth), 0.1);
  ASSERT_EQ(result.attempts.size(), 1u);
  EXPECT_EQ(result.attempts[0].kind, AttemptKind::kPrior);
  ExpectConsistentLadder(result);
}

// Consecutive scans of the demo drive, 2 m apart along the sensor's y axis
// (its x and y bounds are equal, so the bounds do not say which way it
// drives). ICP from identity stalls about half way there, at a fit that
// looks confident; the prior rung's probes along every wide axis must reach
// the answer, whatever the seed that thins the finer levels.
TEST(BoIcpLadder, APriorShortOfTheMotionAlongEitherAxisIsCompleted) {
  const SyntheticDrive drive(41, 7);
  const SyntheticScan source = drive.Scan(39), target = drive.Scan(40);
  const Transform truth = target.T_world_scan.inverse() * source.T_world_scan;
  ASSERT_GT(std::abs(truth(1, 3)), 1.5);  // the motion is along y
  BoIcpConfig config = PresetConfig("C");
  config.automatic.clear();  // the settings `boicp map` chooses for this drive
  config.voxel = 0.82;
  config.refine_voxel = 0.173;
  config.translation_bounds = Eigen::Vector3d(5.13, 5.13, 1.64);
  config.rotation_bounds = Eigen::Vector3d(0.2, 0.2, M_PI);
  config.budget = Budget::kAuto;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    config.seed = seed;
    const RegistrationResult result =
        RegisterPair(source.points, target.points, config, std::nullopt, {}, Transform::Identity());
    EXPECT_LT(TranslationErrorM(result.transform, truth), 0.05) << "seed " << seed;
    EXPECT_LT(RotationErrorDeg(result.transform, truth), 0.2) << "seed " << seed;
  }
}

// The ladder with every rung, and a short search of few iterations.
BoIcpConfig ClimbingConfig() {
  BoIcpConfig config = LadderConfig();
  config.iterations = 4;
  config.retry_when_doubtful = true;
  return config;
}

// The same blobs 100 m from their frames' origin, where no sensor's view
// says whether they overlap.
std::pair<Points, Points> FarUnrelatedBlobs() {
  auto [source, target] = UnrelatedBlobs();
  for (Points* cloud : {&source, &target}) {
    for (Point& p : *cloud) p.x() += 100.0;
  }
  return {source, target};
}

// Nothing fits two unrelated blobs: every rung runs (the prior rung refines
// the feature hypotheses too, so the feature rung does not run again), the
// short search is continued rather than restarted, the retry searches in 6
// DOF with another seed, and no rung's answer is trusted.
TEST(BoIcpLadder, ADoubtfulPairClimbsEveryRung) {
  const auto [source, target] = FarUnrelatedBlobs();
  BoIcpConfig config = ClimbingConfig();
  const RegistrationResult result =
      RegisterPair(source, target, config, std::nullopt, {}, Transform::Identity());
  EXPECT_TRUE(result.doubtful);
  std::vector<AttemptKind> kinds;
  for (const Attempt& a : result.attempts) {
    kinds.push_back(a.kind);
    EXPECT_LT(a.confidence, kTrustedFrom) << AttemptKindName(a.kind);
  }
  ASSERT_EQ(kinds, (std::vector<AttemptKind>{AttemptKind::kPrior, AttemptKind::kShortSearch,
                                             AttemptKind::kSearch, AttemptKind::kSearch}));
  const Attempt& short_search = result.attempts[1];
  const Attempt& rest = result.attempts[2];
  const Attempt& retry = result.attempts[3];
  // The continued search repeats none of the short one's rotation stage; its
  // translation stage starts again only where the best rotation moved its box.
  const int stage_budget = config.random_samples + config.iterations;
  EXPECT_GE(short_search.evaluations + rest.evaluations, 2 * stage_budget);
  EXPECT_LT(rest.evaluations, 2 * stage_budget);
  EXPECT_EQ(retry.mode, SearchMode::kSixDof);
  EXPECT_NE(retry.seed, config.seed);
  EXPECT_EQ(retry.evaluations, 2 * (config.random_samples + config.iterations));
  ExpectConsistentLadder(result);

  // In one 6-DOF stage the short and the continued search spend its budget once.
  config.retry_when_doubtful = false;
  config.mode = SearchMode::kSixDof;
  const RegistrationResult six_dof = RegisterPair(source, target, config);
  ASSERT_EQ(six_dof.attempts.size(), 3u);
  EXPECT_EQ(six_dof.attempts[0].kind, AttemptKind::kFeatures);
  for (const Attempt& a : six_dof.attempts) EXPECT_LT(a.confidence, kTrustedFrom);
  EXPECT_EQ(six_dof.attempts[1].evaluations + six_dof.attempts[2].evaluations, stage_budget);
  EXPECT_EQ(six_dof.attempts.back().kind, AttemptKind::kSearch);
}

// Two unrelated blobs 30 m across, seen from their origin: every answer
// matches little and puts much of the source where the target's sensor saw
// through. The scans do not overlap, so the ladder ends after the short
// search.
TEST(BoIcpLadder, ScansThatDoNotOverlapStopAfterTheShortSearch) {
  auto [source, target] = UnrelatedBlobs();
  for (Points* cloud : {&source, &target}) {
    for (Point& p : *cloud) p *= 3.0;
  }
  const RegistrationResult result =
      RegisterPair(source, target, ClimbingConfig(), std::nullopt, {}, Transform::Identity());
  EXPECT_TRUE(result.doubtful);
  ASSERT_EQ(result.attempts.size(), 2u);
  EXPECT_EQ(result.attempts[0].kind, AttemptKind::kPrior);
  EXPECT_EQ(result.attempts[1].kind, AttemptKind::kShortSearch);
  for (const Attempt& a : result.attempts) {
    EXPECT_LT(a.fitness, 0.1);
    EXPECT_GE(a.features.seen_through, 0.3);
  }
}

// A scan's features are computed by the first of its pairs that reaches the
// feature rung, and the next pair gets the same answer from them as from
// features of its own.
TEST(BoIcpLadder, PairsSharingAScanComputeItsFeaturesOnce) {
  const Points world = MakeSyntheticStreet(11, 15.0);
  const auto scan = [&](double yaw, double x, uint64_t seed) {
    return SimulateScan(world, PoseFromYawTranslation(yaw, {x, 0.0, 1.8}), 30.0, 0.01, seed);
  };
  const Points a = scan(0.0, 0.0, 1), b = scan(2.3, 1.2, 2), c = scan(-1.0, 2.0, 3);
  const BoIcpConfig config = LadderConfig();
  const ScanPyramid pa = BuildScanPyramid(a, config), pb = BuildScanPyramid(b, config),
                    pc = BuildScanPyramid(c, config);
  ASSERT_EQ(std::max(FeatureStep(pa.levels[0].size()), FeatureStep(pb.levels[0].size())),
            std::max(FeatureStep(pb.levels[0].size()), FeatureStep(pc.levels[0].size())))
      << "the test needs both pairs at one feature step";

  const RegistrationResult ab = RegisterPair(pb, pa, config, std::nullopt);
  const RegistrationResult bc = RegisterPair(pb, pc, config, std::nullopt);
  EXPECT_EQ(ab.attempts[0].kind, AttemptKind::kFeatures);
  EXPECT_EQ(bc.attempts[0].kind, AttemptKind::kFeatures);
  EXPECT_EQ(pa.features->computed(), 1u);
  EXPECT_EQ(pb.features->computed(), 1u);
  EXPECT_EQ(pc.features->computed(), 1u);

  const RegistrationResult fresh = RegisterPair(b, c, config);
  EXPECT_TRUE(bc.transform == fresh.transform);
  EXPECT_EQ(bc.confidence, fresh.confidence);
  EXPECT_EQ(bc.answered_by, fresh.answered_by);
}

TEST(BoIcpLadder, ThreadCountDoesNotChangeTheAnswer) {
  const StreetPair pair = MakeStreetPair(2.3);
  BoIcpConfig config = LadderConfig();
  const RegistrationResult a = RegisterPair(pair.source, pair.target, config);
  config.threads = 2;
  const RegistrationResult b = RegisterPair(pair.source, pair.target, config);
  EXPECT_TRUE(a.transform == b.transform);
  EXPECT_EQ(a.confidence, b.confidence);
  EXPECT_EQ(a.answered_by, b.answered_by);
  EXPECT_EQ(a.evaluations, b.evaluations);
}

TEST(BoIcp, StopRequestCancels) {
  const StreetPair pair = MakeStreetPair(0.5);
  RegistrationCallbacks callbacks;
  int polls = 0;
  callbacks.stop_requested = [&] { return ++polls > 3; };
  EXPECT_THROW(RegisterPair(pair.source, pair.target, SmallConfig(SearchMode::kNested),
                            std::nullopt, callbacks),
               Cancelled);
}

TEST(BoIcp, EmptyAfterCroppingIsAnInputError) {
  const StreetPair pair = MakeStreetPair(0.5);
  BoIcpConfig config = SmallConfig(SearchMode::kNested);
  config.max_range = 0.5;
  EXPECT_THROW(RegisterPair(pair.source, pair.target, config), InputError);
}

}  // namespace
}  // namespace boicp
