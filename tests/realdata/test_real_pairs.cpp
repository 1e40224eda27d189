// Config C with automatic settings (no dataset-specific flag) on every
// reference pair of the shared real data, the source turned to an arbitrary
// heading: any yaw for the car, any rotation for the rest; with the default
// ladder and with the paper's fixed budget, and with the ladder under the
// field conditions of bench/field_conditions.hpp. Success per pair:
// rotation and translation error under the dataset's tolerance. A dataset
// passes when at least 95 % of its pairs succeed and no failure goes
// unflagged: every pair that missed is reported doubtful.

#include <cstdio>
#include <filesystem>
#include <random>
#include <tuple>

#include <gtest/gtest.h>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "evaluation.hpp"
#include "field_conditions.hpp"
#include "shared_data.hpp"

namespace boicp {
namespace {

struct DatasetCase {
  std::string name;  // folder under ../shared/data
  PerturbationKind perturbation;
  double max_rotation_deg;
  double max_translation_m;
  bool depth_images;  // 7-Scenes: 16-bit PNG, 1000 per metre, camera-intrinsics.txt
};

std::ostream& operator<<(std::ostream& os, const DatasetCase& c) { return os << c.name; }

// A dataset's reference pairs and how its scans load; `missing` says why
// the test skips when the shared data is absent (then nothing else is read).
struct SharedPairs {
  std::string missing;
  LoadOptions load;
  std::vector<ReferencePair> pairs;
};

SharedPairs ReadSharedPairs(const DatasetCase& dataset) {
  const std::filesystem::path folder = SharedDataFolder(dataset.name);
  SharedPairs shared;
  shared.missing = MissingSharedData(folder);
  if (!shared.missing.empty()) return shared;
  shared.load = SharedDataLoadOptions(folder, dataset.depth_images);
  shared.pairs = ReadPairsCsv((folder / "pairs.csv").string());
  return shared;
}

// Preset C on one thread, as every table of this file was measured.
BoIcpConfig OneThreadConfigC() {
  BoIcpConfig config = PresetConfig("C");
  config.threads = 1;
  return config;
}

// Registers every pair of `dataset` under `condition` with `budget` and
// expects the dataset to pass (see the top of this file).
void ExpectDatasetRecovered(const DatasetCase& dataset, Budget budget,
                            bench::FieldCondition condition) {
  const SharedPairs shared = ReadSharedPairs(dataset);
  if (!shared.missing.empty()) GTEST_SKIP() << shared.missing;
  const LoadOptions& load = shared.load;
  const std::vector<ReferencePair>& pairs = shared.pairs;
  BoIcpConfig config = OneThreadConfigC();
  config.budget = budget;

  std::mt19937_64 rng(20261122);
  std::mt19937_64 field_rng(20261204);  // its own, so the clean draws stay as they were
  int successes = 0, doubtful = 0, retried = 0, silent_failures = 0;
  std::vector<double> runtimes;
  std::printf("%-28s %-28s %9s %9s %7s %6s %6s %6s %6s %6s %4s %-12s %5s\n", "source", "target",
              "rot_deg", "trans_m", "time_s", "fit", "margin", "supp", "pbet", "conf", "try",
              "answered_by", "ok");
  for (const ReferencePair& pair : pairs) {
    const bench::FieldPair field =
        bench::ApplyFieldCondition(condition, LoadPointCloud(pair.source, load).points,
                                   LoadPointCloud(pair.target, load).points, field_rng());
    const Transform perturbation = RandomPerturbation(dataset.perturbation, rng);
    const Points source = TransformPoints(perturbation, field.source);
    const Transform expected = field.Expected(pair.T_target_source, perturbation);
    config.seed = rng();
    const RegistrationResult result = RegisterPair(source, field.target, config);
    const double rot = RotationErrorDeg(result.transform, expected);
    const double trans =
        TranslationErrorM(result.transform, expected, field.ErrorPoint(perturbation));
    const bool ok = rot < dataset.max_rotation_deg && trans < dataset.max_translation_m;
    successes += ok;
    doubtful += result.doubtful;
    silent_failures += !ok && !result.doubtful;
    retried += result.attempts.size() > 1;
    runtimes.push_back(result.runtime_s);
    const ConfidenceFeatures& f = result.features;
    std::printf("%-28s %-28s %9.3f %9.4f %7.2f %6.3f %6.3f %6.3f %6.3f %6.3f %4zu %-12s %5s\n",
                std::filesystem::path(pair.source).filename().c_str(),
                std::filesystem::path(pair.target).filename().c_str(), rot, trans, result.runtime_s,
                f.fitness, f.margin, f.support, f.probability_better, result.confidence,
                result.attempts.size(), RungName(result.answered_by).c_str(), ok ? "yes" : "NO");
    std::fflush(stdout);
  }
  std::sort(runtimes.begin(), runtimes.end());
  std::printf(
      "%s, %s: %d/%zu pairs within %.1f deg and %.3f m; %d doubtful, %d retried; median runtime "
      "%.2f s\n",
      dataset.name.c_str(), bench::FieldConditionName(condition).c_str(), successes, pairs.size(),
      dataset.max_rotation_deg, dataset.max_translation_m, doubtful, retried,
      runtimes[runtimes.size() / 2]);
  EXPECT_GE(successes, static_cast<int>(std::ceil(0.95 * static_cast<double>(pairs.size()))));
  EXPECT_EQ(silent_failures, 0) << "pairs that missed without being reported doubtful";
}

class RealPairs : public ::testing::TestWithParam<std::tuple<DatasetCase, Budget>> {};

TEST_P(RealPairs, AutomaticSettingsRecoverArbitraryHeadings) {
  ExpectDatasetRecovered(std::get<0>(GetParam()), std::get<1>(GetParam()),
                         bench::FieldCondition::kClean);
}

// What field logs do to the scans (far returns, a 90-degree sector cut from
// the source, a sparser sensor, a tilted mount, a frame whose origin is 1 km
// or 5.4e6 m away), with no flags.
class FieldPairs : public ::testing::TestWithParam<std::tuple<DatasetCase, bench::FieldCondition>> {
};

TEST_P(FieldPairs, TheLadderRecoversOrDoubtsUnderFieldConditions) {
  ExpectDatasetRecovered(std::get<0>(GetParam()), Budget::kAuto, std::get<1>(GetParam()));
}

// A car turns about z only; a hand-held camera and a scanned object anyhow.
std::vector<DatasetCase> Datasets() {
  return {{"kitti00", PerturbationKind::kYaw, 2.0, 0.3, false},
          {"7scenes_redkitchen", PerturbationKind::kAnyRotation, 2.0, 0.05, true},
          {"bunny", PerturbationKind::kAnyRotation, 2.0, 0.005, false}};
}

INSTANTIATE_TEST_SUITE_P(SharedData, RealPairs,
                         ::testing::Combine(::testing::ValuesIn(Datasets()),
                                            ::testing::Values(Budget::kAuto, Budget::kFixed)),
                         [](const ::testing::TestParamInfo<std::tuple<DatasetCase, Budget>>& info) {
                           return TestName(std::get<0>(info.param).name + "_" +
                                           BudgetName(std::get<1>(info.param)));
                         });

INSTANTIATE_TEST_SUITE_P(
    SharedData, FieldPairs,
    ::testing::Combine(
        ::testing::ValuesIn(Datasets()),
        ::testing::Values(bench::FieldCondition::kFarReturns, bench::FieldCondition::kSector,
                          bench::FieldCondition::kQuarter, bench::FieldCondition::kTilt,
                          bench::FieldCondition::kFarOrigin, bench::FieldCondition::kGeoOrigin)),
    [](const ::testing::TestParamInfo<std::tuple<DatasetCase, bench::FieldCondition>>& info) {
      return TestName(std::get<0>(info.param).name + "_" +
                      bench::FieldConditionName(std::get<1>(info.param)));
    });

// Each reference pair as a drive's consecutive scans meet the ladder: in
// their own frames, from the identity guess. The prior rung must not stop
// where ICP from the guess stalls (7-Scenes 250 -> 275 stalled 23 cm short
// with every probe, trusted, until the feature hypotheses were refined
// beside them): every trusted answer is right, and 95 % are right.
class RealPairsFromAGuess : public ::testing::TestWithParam<DatasetCase> {};

TEST_P(RealPairsFromAGuess, NoAnswerFromTheIdentityGuessIsWrongAndTrusted) {
  const DatasetCase& dataset = GetParam();
  const SharedPairs shared = ReadSharedPairs(dataset);
  if (!shared.missing.empty()) GTEST_SKIP() << shared.missing;
  const LoadOptions& load = shared.load;
  const std::vector<ReferencePair>& pairs = shared.pairs;
  BoIcpConfig config = OneThreadConfigC();
  config.seed = 20261207;
  int right = 0;
  for (const ReferencePair& pair : pairs) {
    const RegistrationResult result = RegisterPair(LoadPointCloud(pair.source, load).points,
                                                   LoadPointCloud(pair.target, load).points, config,
                                                   std::nullopt, {}, Transform::Identity());
    const double rot = RotationErrorDeg(result.transform, pair.T_target_source);
    const double trans = TranslationErrorM(result.transform, pair.T_target_source);
    const bool ok = rot < dataset.max_rotation_deg && trans < dataset.max_translation_m;
    right += ok;
    std::printf("%-28s %-28s %8.3f deg %8.4f m  confidence %.4f  %-12s %s\n",
                std::filesystem::path(pair.source).filename().c_str(),
                std::filesystem::path(pair.target).filename().c_str(), rot, trans,
                result.confidence, RungName(result.answered_by).c_str(), ok ? "yes" : "NO");
    EXPECT_TRUE(ok || result.doubtful)
        << pair.source << " -> " << pair.target << ": wrong and trusted";
  }
  EXPECT_GE(right, static_cast<int>(std::ceil(0.95 * static_cast<double>(pairs.size()))));
}

INSTANTIATE_TEST_SUITE_P(SharedData, RealPairsFromAGuess, ::testing::ValuesIn(Datasets()),
                         [](const ::testing::TestParamInfo<DatasetCase>& info) {
                           return TestName(info.param.name);
                         });

// A street scan against a kitchen: nothing fits, so every rung of the
// ladder is doubtful and so is the answer.
TEST(RealPairsUnrelated, AStreetAgainstARoomIsDoubtful) {
  const std::filesystem::path kitti = SharedDataFolder("kitti00");
  const std::filesystem::path kitchen = SharedDataFolder("7scenes_redkitchen");
  for (const std::filesystem::path& folder : {kitti, kitchen}) {
    if (const std::string missing = MissingSharedData(folder); !missing.empty())
      GTEST_SKIP() << missing;
  }
  const Points street = LoadPointCloud(ReadPairsCsv((kitti / "pairs.csv").string()).front().source,
                                       SharedDataLoadOptions(kitti, false))
                            .points;
  const Points room = LoadPointCloud(ReadPairsCsv((kitchen / "pairs.csv").string()).front().source,
                                     SharedDataLoadOptions(kitchen, true))
                          .points;
  BoIcpConfig config = PresetConfig("C");
  config.threads = 1;
  const RegistrationResult result = RegisterPair(street, room, config);
  std::printf("street onto room: fitness %.3f margin %.3f confidence %.3f, answered by %s\n",
              result.fitness, result.features.margin, result.confidence,
              RungName(result.answered_by).c_str());
  EXPECT_TRUE(result.doubtful);
  EXPECT_EQ(result.attempts.back().kind, AttemptKind::kSearch);  // it climbed to the retry
}

}  // namespace
}  // namespace boicp
