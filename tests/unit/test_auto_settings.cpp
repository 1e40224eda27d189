// Settings chosen from the clouds: they follow the scene's scale, the
// sensor's view and the user's overrides.

#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/auto_settings.hpp"
#include "boicp/registration/bo_icp.hpp"

namespace boicp {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A LiDAR scan of the generated street, 1.8 m above level ground.
Points StreetScan() {
  const std::vector<SyntheticScan> drive = MakeSyntheticDrive(1, 3);
  return drive.front().points;
}

// A depth camera's view: a wall 3 m ahead and a floor 1.5 m below, inside a
// 60-degree cone about +z (the camera frame's forward axis).
Points CameraView() {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Points points;
  for (int i = 0; i < 20000; ++i) {
    const double x = 1.5 * u(rng), depth = 1.5 + 1.5 * (u(rng) + 1.0);
    points.push_back(i % 2 == 0 ? Point(x, 1.5 * u(rng), 3.0) : Point(x, 1.5, depth));
  }
  return points;
}

Points Scaled(const Points& points, double factor) {
  Points out;
  for (const Point& p : points) out.push_back(factor * p);
  return out;
}

TEST(AutoSettings, LevelLidarTurnsOnlyAboutZ) {
  const Points scan = StreetScan();
  const ChosenSettings chosen = ChooseSettingsForClouds({scan, scan}, std::nullopt, 1);
  EXPECT_EQ(chosen.sensor, SensorKind::kLidar);
  EXPECT_DOUBLE_EQ(chosen.rotation_bounds.z(), M_PI);
  EXPECT_LT(chosen.rotation_bounds.x(), 0.5);
  EXPECT_LT(chosen.rotation_bounds.y(), 0.5);
  // The ground holds the height: z gets far less room than x and y.
  EXPECT_LT(chosen.translation_bounds.z(), 0.5 * chosen.translation_bounds.x());
  EXPECT_GT(chosen.map_max_range, 0.0);
}

Points WithoutAzimuths(const Points& points, double from_deg, double to_deg) {
  Points kept;
  for (const Point& p : points) {
    const double azimuth = std::atan2(p.y(), p.x()) * 180.0 / M_PI;
    if (azimuth < from_deg || azimuth >= to_deg) kept.push_back(p);
  }
  return kept;
}

// A ring with a sector blocked (an operator's back, a side mount) is still a
// LiDAR's; with most of it blocked it is a view, and the reason says which.
TEST(AutoSettings, TheSensorSaysWhyAndARingWithAGapIsARing) {
  const Points scan = StreetScan();
  const ChosenSettings full = ChooseSettingsForClouds({scan, scan}, std::nullopt, 1);
  EXPECT_EQ(full.sensor, SensorKind::kLidar);
  EXPECT_THAT(full.sensor_reason, HasSubstr("ring covering 360 deg"));
  // The sensor is 1.8 m up; the plane is found within half a search voxel.
  const size_t ground = full.sensor_reason.find("ground plane ");
  ASSERT_NE(ground, std::string::npos) << full.sensor_reason;
  EXPECT_NEAR(std::stod(full.sensor_reason.substr(ground + 13)), 1.8, 0.5 * full.voxel);
  EXPECT_THAT(full.sensor_reason, HasSubstr("m below the origin"));

  const Points blocked = WithoutAzimuths(scan, -60.0, 40.0);  // 100 degrees behind an operator
  const ChosenSettings gap = ChooseSettingsForClouds({scan, blocked}, std::nullopt, 1);
  EXPECT_EQ(gap.sensor, SensorKind::kLidar);
  EXPECT_EQ(gap.rotation_bounds, full.rotation_bounds);
  EXPECT_THAT(gap.sensor_reason, HasSubstr("ring covering 260 deg"));

  const Points half = WithoutAzimuths(scan, -90.0, 90.0);
  const ChosenSettings view = ChooseSettingsForClouds({scan, half}, std::nullopt, 1);
  EXPECT_NE(view.sensor, SensorKind::kLidar);
  EXPECT_THAT(view.sensor_reason, HasSubstr("one-sided view"));

  const Points camera = CameraView();
  EXPECT_THAT(ChooseSettingsForClouds({camera}, std::nullopt, 1).sensor_reason,
              HasSubstr("one-sided view (mean direction 0."));
  EXPECT_EQ(
      ChooseSettingsForClouds({camera}, DeclareSensor(std::nullopt, CloudFormat::kDepthPng), 1)
          .sensor_reason,
      "depth images");
}

TEST(AutoSettings, ConeOfViewMayTurnAnyhow) {
  const Points view = CameraView();
  for (CloudFormat format : {CloudFormat::kAuto, CloudFormat::kDepthPng}) {
    const ChosenSettings chosen =
        ChooseSettingsForClouds({view}, DeclareSensor(std::nullopt, format), 1);
    EXPECT_NE(chosen.sensor, SensorKind::kLidar);
    EXPECT_EQ(chosen.rotation_bounds, Eigen::Vector3d(M_PI, M_PI / 2, M_PI));
  }
  EXPECT_EQ(ChooseSettingsForClouds({view}, DeclareSensor(std::nullopt, CloudFormat::kDepthPng), 1)
                .sensor,
            SensorKind::kDepthCamera);
}

// --sensor replaces what the format and the geometry say, and the reason
// says it was set; a LiDAR's small rotation box still needs level ground.
TEST(AutoSettings, ASetSensorOverridesTheFormatAndTheGeometry) {
  const Points street = StreetScan();
  const ChosenSettings depth = ChooseSettingsForClouds(
      {street}, DeclareSensor(SensorKind::kDepthCamera, CloudFormat::kKittiBin), 1);
  EXPECT_EQ(depth.sensor, SensorKind::kDepthCamera);
  EXPECT_EQ(depth.sensor_reason, "set by --sensor");
  EXPECT_EQ(depth.rotation_bounds, Eigen::Vector3d(M_PI, M_PI / 2, M_PI));

  const ChosenSettings lidar =
      ChooseSettingsForClouds({street}, DeclareSensor(SensorKind::kLidar, CloudFormat::kAuto), 1);
  EXPECT_EQ(lidar.sensor, SensorKind::kLidar);
  EXPECT_THAT(lidar.sensor_reason, HasSubstr("set by --sensor, ground plane"));
  EXPECT_LT(lidar.rotation_bounds.x(), 0.5);

  const Points view = CameraView();
  const ChosenSettings tilted =
      ChooseSettingsForClouds({view}, DeclareSensor(SensorKind::kLidar, CloudFormat::kAuto), 1);
  EXPECT_EQ(tilted.sensor, SensorKind::kLidar);
  EXPECT_EQ(tilted.sensor_reason,
            "set by --sensor, no ground plane below the origin in every scan");
  EXPECT_EQ(tilted.rotation_bounds, Eigen::Vector3d(M_PI, M_PI / 2, M_PI));

  EXPECT_EQ(
      ChooseSettingsForClouds({street}, DeclareSensor(SensorKind::kOther, CloudFormat::kAuto), 1)
          .sensor,
      SensorKind::kOther);
}

TEST(AutoSettings, TheSensorSettingReadsItsWordsAndNamesTheChoices) {
  EXPECT_EQ(ParseSensorSetting("auto"), std::nullopt);
  EXPECT_EQ(ParseSensorSetting("lidar"), SensorKind::kLidar);
  EXPECT_EQ(ParseSensorSetting("depth"), SensorKind::kDepthCamera);
  EXPECT_EQ(ParseSensorSetting("object"), SensorKind::kOther);
  for (const char* word : {"auto", "lidar", "depth", "object"}) {
    EXPECT_EQ(SensorSettingName(ParseSensorSetting(word)), word);
  }
  try {
    ParseSensorSetting("camera");
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown sensor 'camera' (expected lidar, depth, object or auto)");
  }
}

TEST(AutoSettings, LengthsFollowTheScenesScale) {
  const Points view = CameraView();
  const Points large = Scaled(view, 10.0);
  const ChosenSettings small = ChooseSettingsForClouds({view}, std::nullopt, 1);
  const ChosenSettings big = ChooseSettingsForClouds({large}, std::nullopt, 1);
  EXPECT_NEAR(big.voxel, 10.0 * small.voxel, 1e-6 * big.voxel);
  EXPECT_TRUE(big.translation_bounds.isApprox(10.0 * small.translation_bounds, 1e-6));
  EXPECT_NEAR(big.map_resolution, 10.0 * small.map_resolution, 1e-6 * big.map_resolution);
  EXPECT_EQ(big.rotation_bounds, small.rotation_bounds);
}

// A cloud in millimetres against one in metres is not a pair of one scene
// to choose settings for; a view ten times larger may be.
TEST(AutoSettings, CloudsInOtherUnitsAreAnErrorNamingBothScales) {
  const Points metres = CameraView();
  const Points millimetres = Scaled(metres, 1000.0);
  const Points ten_times = Scaled(metres, 10.0);
  EXPECT_NO_THROW(ChooseSettingsForClouds({metres, ten_times}, std::nullopt, 1));
  try {
    ChooseSettingsForClouds({millimetres, metres}, std::nullopt, 1);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("differ in scale by a factor of about 1000"));
    EXPECT_THAT(e.what(), HasSubstr("do they share units?"));
    EXPECT_THAT(e.what(), HasSubstr("--scale-source 0.001"));
  }
  EXPECT_THROW(ChooseSettingsForClouds({metres, millimetres}, std::nullopt, 1), InputError);
}

// 3 % of the camera's returns through a window, 60-150 m out in one
// direction: they drag a centroid and an RMS radius, not the settings.
TEST(AutoSettings, FarReturnsThroughAWindowAreSetAside) {
  const Points view = CameraView();
  Points with_window = view;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> across(-0.3, 0.3), range(60.0, 150.0);
  const size_t added = 3 * view.size() / 100;
  for (size_t i = 0; i < added; ++i) {
    with_window.push_back(range(rng) * Point(across(rng), across(rng), 1.0).normalized());
  }
  const CloudStatistics clean = MeasureCloud(view, 1);
  const CloudStatistics window = MeasureCloud(with_window, 1);
  EXPECT_EQ(clean.far_returns, 0u);
  EXPECT_EQ(window.far_returns, added);
  const ChosenSettings a = ChooseSettings({clean}, std::nullopt);
  const ChosenSettings b = ChooseSettings({window}, std::nullopt);
  EXPECT_NEAR(b.voxel, a.voxel, 0.03 * a.voxel);
  EXPECT_TRUE(b.translation_bounds.isApprox(a.translation_bounds, 0.03));
  EXPECT_NEAR(b.map_max_range, a.map_max_range, 0.03 * a.map_max_range);
  EXPECT_THAT(b.far_returns, ElementsAre(added));
}

TEST(AutoSettings, TooSmallOrFlatCloudIsOneClearError) {
  const Points few(50, Point(1, 2, 3));
  try {
    MeasureCloud(few, 1);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("too few"));
    EXPECT_THAT(e.what(), HasSubstr("--voxel"));
  }
  const Points one_place(500, Point(1, 2, 3));
  EXPECT_THROW(MeasureCloud(one_place, 1), InputError);
  // Most points in one place leave no median distance to call others far by.
  Points mostly_one_place = one_place;
  for (int i = 0; i < 200; ++i) mostly_one_place.push_back(Point(i, 0.5 * i, 1.0));
  const CloudStatistics stats = MeasureCloud(mostly_one_place, 1);
  EXPECT_EQ(stats.far_returns, 0u);
  EXPECT_GT(stats.rms_radius, 10.0);
}

TEST(AutoSettings, OnlyFieldsLeftAutomaticAreChosen) {
  const Points scan = StreetScan();
  const ChosenSettings chosen = ChooseSettingsForClouds({scan}, std::nullopt, 1);
  BoIcpConfig config = PresetConfig("C");
  config.voxel = 0.5;
  config.MarkSet("voxel");
  const std::vector<std::string> set = ApplyChosenSettings(chosen, config);
  EXPECT_THAT(set, ElementsAre("refine_voxel", "objective_truncation", "translation_bounds",
                               "rotation_bounds"));
  EXPECT_DOUBLE_EQ(config.voxel, 0.5);
  EXPECT_EQ(config.retry_voxel, 0.0);  // a voxel the user set is kept for the retry too
  EXPECT_DOUBLE_EQ(config.objective_truncation, 0.75);
  EXPECT_LE(config.refine_voxel, 0.5 / 4);
  EXPECT_TRUE(config.automatic.empty());

  BoIcpConfig fixed = PresetConfig("C");
  fixed.automatic.clear();
  EXPECT_TRUE(ApplyChosenSettings(chosen, fixed).empty());
  EXPECT_DOUBLE_EQ(fixed.voxel, 0.6);
}

TEST(AutoSettings, PresetsKeepTheirVoxelRatio) {
  const Points scan = StreetScan();
  const ChosenSettings chosen = ChooseSettingsForClouds({scan}, std::nullopt, 1);
  BoIcpConfig a = PresetConfig("A"), c = PresetConfig("C");
  ApplyChosenSettings(chosen, a);
  ApplyChosenSettings(chosen, c);
  EXPECT_NEAR(a.voxel / c.voxel, 0.7 / 0.6, 1e-12);
  EXPECT_DOUBLE_EQ(c.voxel, chosen.voxel);
  EXPECT_GT(c.retry_voxel, c.voxel);
}

TEST(AutoSettings, RegisterPairReportsWhatItChose) {
  const std::vector<SyntheticScan> drive = MakeSyntheticDrive(2, 8);
  BoIcpConfig config = PresetConfig("A");
  config.iterations = 5;
  config.retry_when_doubtful = false;
  const RegistrationResult result =
      RegisterPair(drive[0].points, drive[1].points, config, std::nullopt);
  EXPECT_THAT(result.auto_fields, ElementsAre("voxel", "refine_voxel", "objective_truncation",
                                              "translation_bounds", "rotation_bounds"));
  EXPECT_TRUE(result.config.automatic.empty());
  EXPECT_GT(result.config.voxel, 0.0);
  EXPECT_EQ(result.attempts.size(), 1u);
}

}  // namespace
}  // namespace boicp
