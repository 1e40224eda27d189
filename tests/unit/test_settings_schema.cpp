// The settings schema: every field reaches BoIcpConfig from its flag, every
// field survives run.json, and a config as used (register --json, pair
// files, run.json's chosen) names every registration setting, resolved, and
// reads back.

#include <cmath>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/settings/triple_text.hpp"
#include "boicp/util/types.hpp"
#include "settings_examples.hpp"

namespace boicp::settings {
namespace {

TEST(SettingSchema, NamesAreUniqueAndEveryApiGapIsExplained) {
  std::set<std::string> names, json_keys;
  for (const SettingField& field : SettingSchema()) {
    EXPECT_TRUE(names.insert(field.name).second) << field.name;
    EXPECT_TRUE(json_keys.insert(field.json_key).second) << field.json_key;
    const bool everywhere =
        (field.frontends & (kRegister | kMap | kSubmit)) == (kRegister | kMap | kSubmit) &&
        field.message != ProtoMessage::kNone;
    EXPECT_EQ(field.absent_because == nullptr, everywhere) << field.name;
    EXPECT_EQ(field.message == ProtoMessage::kNone, std::string(field.proto_field).empty())
        << field.name;
    // Limits bound what a request gives a number.
    const bool bounded = std::isfinite(field.limits.lower) || std::isfinite(field.limits.upper);
    const bool number = std::visit(
        [](const auto& binding) { return !kIsPlainBinding<std::decay_t<decltype(binding)>>; },
        field.binding);
    EXPECT_TRUE(!bounded || (number && field.message != ProtoMessage::kNone)) << field.name;
    // Whatever the API takes, submit must be able to send.
    if (field.message != ProtoMessage::kNone) {
      EXPECT_TRUE(field.frontends & kSubmit) << field.name;
    }
  }
}

TEST(SettingSchema, EveryRegisterFlagReachesTheConfigAndSurvivesJson) {
  const RequestedSettings given = ParseFlags(kRegister, ExampleArguments(kRegister));
  const BoIcpConfig config = ConfigFromSettings(given);
  EXPECT_EQ(config.preset, "B");
  EXPECT_EQ(config.mode, SearchMode::kSixDof);
  EXPECT_EQ(config.budget, Budget::kFixed);
  EXPECT_EQ(config.sensor, SensorKind::kDepthCamera);
  EXPECT_FALSE(config.retry_when_doubtful);
  EXPECT_TRUE(config.automatic.empty());
  for (const SettingField& field : SettingSchema()) {
    if ((field.frontends & kRegister) == 0) continue;
    std::visit(
        [&](const auto& binding) {
          using Binding = std::decay_t<decltype(binding)>;
          if constexpr (std::is_same_v<Binding, OptionalBinding<double>> ||
                        std::is_same_v<Binding, OptionalBinding<int>> ||
                        std::is_same_v<Binding, OptionalBinding<uint64_t>> ||
                        std::is_same_v<Binding, OptionalBinding<Eigen::Vector3d>>) {
            ASSERT_TRUE(given.*binding.requested) << field.name << " was not parsed";
            ASSERT_TRUE(binding.config != nullptr) << field.name;
            EXPECT_EQ(config.*binding.config, *(given.*binding.requested)) << field.name;
          }
        },
        field.binding);
  }

  // config -> JSON -> config
  const RequestedSettings as_used = SettingsFromConfig(config);
  RequestedSettings read_back;
  SettingsFromJson(AllFields(as_used), kRegister | kMap | kSubmit | kBench, "test", read_back);
  EXPECT_EQ(AllFields(read_back), AllFields(as_used));
  EXPECT_EQ(AllFields(SettingsFromConfig(ConfigFromSettings(read_back))), AllFields(as_used));
}

TEST(SettingSchema, EveryMapAndSubmitFlagSurvivesRunJson) {
  for (const Frontend frontend : {kMap, kSubmit, kBench}) {
    const RequestedSettings given = ParseFlags(frontend, ExampleArguments(frontend));
    RequestedSettings read_back;
    SettingsFromJson(SettingsToJson(given, frontend), frontend, "run.json", read_back);
    EXPECT_EQ(AllFields(read_back), AllFields(given)) << frontend;
    EXPECT_NE(AllFields(given), AllFields(RequestedSettings())) << frontend;
  }
}

TEST(SettingSchema, ConfigAsUsedNamesEveryRegistrationSettingAndReadsBack) {
  const BoIcpConfig config = ConfigFromSettings(ParseFlags(kRegister, ExampleArguments(kRegister)));
  const nlohmann::json used = ConfigToJson(config);
  std::set<std::string> expected;
  for (const SettingField& field : SettingSchema()) {
    if ((field.frontends & kRegister) != 0) expected.insert(field.name);
  }
  expected.erase("fixed_settings");
  std::set<std::string> keys;
  for (const auto& item : used.items()) keys.insert(item.key());
  EXPECT_EQ(keys, expected);
  EXPECT_EQ(used["preset"], "B");
  EXPECT_EQ(used["no_retry"], true);
  EXPECT_EQ(used["budget"], "fixed");
  EXPECT_EQ(used["sensor"], "depth");
  EXPECT_EQ(used["rotation_bounds"], nlohmann::json({0.25, 0.5, 1.25}));

  const BoIcpConfig read_back = ConfigFromJson(used, "test");
  EXPECT_EQ(ConfigToJson(read_back), used);
  EXPECT_TRUE(read_back.automatic.empty());
  EXPECT_EQ(AllFields(SettingsFromConfig(read_back)), AllFields(SettingsFromConfig(config)));

  nlohmann::json bad = used;
  bad["budget"] = "nope";
  EXPECT_THROW(ConfigFromJson(bad, "test"), InputError);
  bad = used;
  bad["voxel"] = "fine";
  EXPECT_THROW(ConfigFromJson(bad, "test"), InputError);
  bad["voxel"] = -1.0;
  EXPECT_THROW(ConfigFromJson(bad, "test"), InputError);
}

TEST(SettingSchema, ConfigAsUsedReportsTheDerivedValues) {
  BoIcpConfig config = PresetConfig("C");
  config.voxel = 0.8;
  config.max_correspondence_distance = 0.0;  // 0 = 3 x voxel
  config.objective_truncation = 0.0;         // 0 = 1.5 x voxel
  config.refine_voxel = 0.0;                 // 0 = voxel / 4
  const nlohmann::json used = ConfigToJson(config);
  EXPECT_DOUBLE_EQ(used["max_correspondence"].get<double>(), config.EffectiveMaxCorrespondence());
  EXPECT_DOUBLE_EQ(used["objective_truncation"].get<double>(), config.EffectiveTruncation());
  EXPECT_DOUBLE_EQ(used["refine_voxel"].get<double>(), config.EffectiveRefineVoxel());
  EXPECT_DOUBLE_EQ(used["max_correspondence"].get<double>(), 2.4);
  EXPECT_DOUBLE_EQ(used["objective_truncation"].get<double>(), 1.2);
  EXPECT_DOUBLE_EQ(used["refine_voxel"].get<double>(), 0.2);
}

TEST(SettingSchema, MapAndSubmitSpellTheScanRangeApartFromTheRayCut) {
  const RequestedSettings map =
      ParseFlags(kMap, {"test", "--max-range", "30", "--scan-max-range", "80"});
  EXPECT_EQ(map.max_range, 30.0);
  EXPECT_EQ(map.scan_max_range, 80.0);
  const RequestedSettings reg = ParseFlags(kRegister, {"test", "--max-range", "80"});
  EXPECT_EQ(reg.scan_max_range, 80.0);
  EXPECT_FALSE(reg.max_range);
}

TEST(SettingSchema, BoundsAreCheckedWhenTheCommandRunsAndSnapToPi) {
  RequestedSettings settings;
  FlagTexts texts;
  CLI::App app;
  AddSettingFlags(app, kRegister, settings, texts);
  const char* argv[] = {"test", "--rotation-bounds", "0.2,0.2,pi", "--translation-bounds", "1,2"};
  ASSERT_NO_THROW(app.parse(5, argv));
  EXPECT_THROW(ApplyFlagTexts(texts, kRegister, settings), InputError);
  texts.erase("translation_bounds");
  ApplyFlagTexts(texts, kRegister, settings);
  const BoIcpConfig config = ConfigFromSettings(settings);
  EXPECT_EQ(config.rotation_bounds, Eigen::Vector3d(0.2, 0.2, M_PI));
  EXPECT_THAT(config.automatic, ::testing::Not(::testing::Contains("rotation_bounds")));
  EXPECT_THAT(config.automatic, ::testing::Contains("translation_bounds"));
}

TEST(SettingSchema, OldRunJsonStillReads) {
  const nlohmann::json old = {{"config", "A"},
                              {"mode", "nested"},
                              {"voxel", nullptr},
                              {"random_samples", 4},
                              {"iterations", nullptr},
                              {"rotation_bounds", "0.2,0.2,pi"},
                              {"translation_bounds", ""},
                              {"seed", 5},
                              {"fixed_settings", false},
                              {"no_retry", true},
                              {"resolution", 0.1},
                              {"max_range", nullptr}};
  RequestedSettings s;
  SettingsFromJson(old, kMap, "run.json", s);
  EXPECT_EQ(s.preset, "A");
  EXPECT_EQ(s.random_samples, 4);
  EXPECT_FALSE(s.iterations);
  EXPECT_EQ(s.rotation_bounds, Eigen::Vector3d(0.2, 0.2, M_PI));
  EXPECT_FALSE(s.translation_bounds);
  EXPECT_EQ(s.seed, 5u);
  EXPECT_TRUE(s.no_retry);
  EXPECT_EQ(s.budget, "auto");  // run.json from before the budget existed
  EXPECT_EQ(s.resolution, 0.1);
  EXPECT_FALSE(s.max_range);
  nlohmann::json bad = old;
  bad["seed"] = "five";
  EXPECT_THROW(SettingsFromJson(bad, kMap, "run.json", s), InputError);
}

TEST(SettingSchema, BudgetIsAutoUnlessFixedOnEveryFrontEnd) {
  for (const Frontend frontend : {kRegister, kMap, kSubmit}) {
    EXPECT_EQ(ConfigFromSettings(ParseFlags(frontend, {"test"})).budget, Budget::kAuto);
    const RequestedSettings fixed = ParseFlags(frontend, {"test", "--budget", "fixed"});
    EXPECT_EQ(ConfigFromSettings(fixed).budget, Budget::kFixed) << frontend;
    RequestedSettings read_back;
    SettingsFromJson(SettingsToJson(fixed, frontend), frontend, "run.json", read_back);
    EXPECT_EQ(read_back.budget, "fixed") << frontend;
  }
  EXPECT_EQ(SettingsFromConfig(PresetConfig("A")).budget, "auto");
}

// An unknown word is one error naming the flag as typed and the words it takes.
TEST(SettingSchema, AnUnknownWordNamesItsFlagAndTheWordsAllowed) {
  const std::pair<const char*, const char*> cases[] = {
      {"--budget", "--budget: unknown budget 'nope' (expected auto or fixed)"},
      {"--sensor", "--sensor: unknown sensor 'nope' (expected lidar, depth, object or auto)"},
      {"--mode", "--mode: unknown search mode 'nope' (expected nested or 6dof)"},
      {"--icp-objective",
       "--icp-objective: unknown ICP objective 'nope' (expected point or plane)"},
      {"--config", "--config: unknown preset 'nope' (expected A, B or C)"}};
  for (const Frontend frontend : {kRegister, kMap, kSubmit}) {
    for (const auto& [flag, message] : cases) {
      try {
        ParseFlags(frontend, {"test", flag, "nope"});
        ADD_FAILURE() << flag << " nope accepted";
      } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), message);
      }
    }
  }
}

TEST(SettingSchema, MapSettingsKeepDefaultsAndValidate) {
  RequestedSettings s;
  s.resolution = 0.1;
  s.prob_hit = 0.8;
  const MapBuildSettings map = MapBuildFromSettings(s);
  EXPECT_EQ(map.occupancy.resolution, 0.1);
  EXPECT_EQ(map.occupancy.prob_hit, 0.8);
  EXPECT_EQ(map.occupancy.prob_miss, OccupancySettings().prob_miss);
  s.cloud_voxel = -1.0;
  EXPECT_THROW(MapBuildFromSettings(s), InputError);
  EXPECT_FALSE(MapAutoFromSettings(s).resolution);
  EXPECT_TRUE(MapAutoFromSettings(s).max_range);
}

TEST(SettingSchema, BoundsTextIsShortAndExact) {
  EXPECT_EQ(FormatTriple(Eigen::Vector3d(0.2, 0.5, 4.0)), "0.2,0.5,4");
  const Eigen::Vector3d turn(M_PI, M_PI / 2, 1.0 / 3.0);
  EXPECT_EQ(ParseTriple(FormatTriple(turn), "test"), turn);
}

}  // namespace
}  // namespace boicp::settings
