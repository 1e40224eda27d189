// Which way is up in a map (core/map_up): a depth-camera room built from
// the 7-Scenes reference poses must find gravity, a generated LiDAR street
// must keep z, and maps without horizontal surfaces fall back with a reason.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "boicp/io/scan_folder.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/map_preview.hpp"
#include "boicp/mapping/map_up.hpp"

#ifndef BOICP_SHARED_DATA_DIR
#define BOICP_SHARED_DATA_DIR ""
#endif

namespace boicp {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

// Fuses `scans` at `poses` into an OctoMap in a temporary file and reads
// its occupied cells back, as the preview does.
OccupiedCells FuseToCells(const std::vector<ScanSource>& scans, const std::vector<Transform>& poses,
                          double resolution, double max_range, const std::string& name) {
  const fs::path bt = fs::temp_directory_path() /
                      ("boicp_map_up_" + std::to_string(::getpid()) + "_" + name + ".bt");
  MapBuildSettings settings;
  settings.occupancy.resolution = resolution;
  settings.occupancy.max_range = max_range;
  MapOutputPaths outputs;
  outputs.octomap_bt = bt.string();
  FuseScans(scans, poses, settings, outputs);
  OccupiedCells cells = ReadOccupiedCells(bt.string());
  fs::remove(bt);
  return cells;
}

TEST(DetectUp, SevenScenesRoomFindsGravity) {
  const fs::path folder = fs::path(BOICP_SHARED_DATA_DIR) / "7scenes_redkitchen";
  if (!fs::exists(folder / "gravity-direction.txt")) {
    GTEST_SKIP() << "real data folder '" << folder.string()
                 << "' (BOICP_SHARED_DATA_DIR, ../shared/data) is absent";
  }
  // gravity-direction.txt: gravity (pointing down) in the 7-Scenes world
  // frame, the frame of the pose files (PROVENANCE.txt).
  Eigen::Vector3d gravity;
  std::ifstream(folder / "gravity-direction.txt") >> gravity.x() >> gravity.y() >> gravity.z();
  ScanFolderOptions options;
  options.stride = 10;  // 18 of the 180 frames, spread over the whole trajectory
  const ScanFolder scans = ReadScanFolder(folder.string(), options);
  std::vector<Transform> poses;
  for (const auto& pose : scans.reference_poses) {
    ASSERT_TRUE(pose.has_value());
    poses.push_back(*pose);  // T_world_camera: the map frame is the 7-Scenes world
  }
  const OccupiedCells cells = FuseToCells(scans.scans, poses, 0.05, 4.0, "7scenes");

  UpDetectionOptions up_options;
  up_options.sensor_up = Eigen::Vector3d(0, -1, 0);  // camera y points down
  const UpDirection up = DetectUp(cells.centres, cells.sizes, cells.resolution, poses, up_options);
  std::printf("7-Scenes: %zu cells, detected up %.3f %.3f %.3f, %.2f degrees from -gravity (%s)\n",
              cells.centres.size(), up.up.x(), up.up.y(), up.up.z(), AngleDeg(up.up, -gravity),
              up.reason.c_str());
  EXPECT_TRUE(up.detected) << up.reason;
  EXPECT_LT(AngleDeg(up.up, -gravity), 10.0) << up.reason;
}

TEST(DetectUp, LidarStreetKeepsZ) {
  const Points world = MakeSyntheticStreet(7);
  std::vector<ScanSource> scans;
  std::vector<Transform> poses;
  const fs::path dir = fs::temp_directory_path() / ("boicp_map_up_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (int i = 0; i < 3; ++i) {
    const Transform pose = PoseFromYawTranslation(0.05 * i, {-4.0 + 3.0 * i, 0.2 * i, 1.8});
    ScanSource scan;
    scan.path = (dir / ("scan" + std::to_string(i) + ".xyz")).string();
    WriteXyz(scan.path, SimulateScan(world, pose, 30.0, 0.02, 10 + static_cast<uint64_t>(i)));
    scans.push_back(scan);
    poses.push_back(pose);
  }
  const OccupiedCells cells = FuseToCells(scans, poses, 0.3, 0.0, "street");
  fs::remove_all(dir);
  for (const bool lidar_prior : {false, true}) {
    UpDetectionOptions options;
    if (lidar_prior) options.sensor_up = Eigen::Vector3d::UnitZ();
    const UpDirection up = DetectUp(cells.centres, cells.sizes, cells.resolution, poses, options);
    std::printf("street (%s prior): %.2f degrees from z (%s)\n", lidar_prior ? "LiDAR" : "no",
                AngleDeg(up.up, Eigen::Vector3d::UnitZ()), up.reason.c_str());
    EXPECT_TRUE(up.detected) << up.reason;
    EXPECT_LT(AngleDeg(up.up, Eigen::Vector3d::UnitZ()), 2.0) << up.reason;
  }
}

TEST(DetectUp, FallsBackWithAReason) {
  // Too few cells.
  const UpDirection few = DetectUp({{0, 0, 0}, {1, 0, 0}}, {0.1, 0.1}, 0.1, {});
  EXPECT_FALSE(few.detected);
  EXPECT_EQ(few.up, Eigen::Vector3d::UnitZ());
  EXPECT_THAT(few.reason, HasSubstr("too few"));

  // Only vertical walls (normals along x and y): nothing faces the prior.
  Points centres;
  std::vector<double> sizes;
  for (double a = 0; a < 4; a += 0.1) {
    for (double z = 0; z < 3; z += 0.1) {
      centres.emplace_back(a, 0, z);
      centres.emplace_back(0, a, z);
      sizes.insert(sizes.end(), {0.1, 0.1});
    }
  }
  const UpDirection walls = DetectUp(centres, sizes, 0.1, {});
  EXPECT_FALSE(walls.detected);
  EXPECT_EQ(walls.up, Eigen::Vector3d::UnitZ());
  EXPECT_THAT(walls.reason, HasSubstr("no family of horizontal surfaces"));

  // With a camera prior and no horizontal surface, up is the cameras' up.
  UpDetectionOptions camera;
  camera.sensor_up = Eigen::Vector3d(0, -1, 0);
  Transform level = Transform::Identity();  // camera y (down) along the map's -z
  level.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const UpDirection from_cameras = DetectUp({{0, 0, 0}}, {0.1}, 0.1, {level}, camera);
  EXPECT_FALSE(from_cameras.detected);
  EXPECT_LT(AngleDeg(from_cameras.up, Eigen::Vector3d::UnitZ()), 1e-6);
}

}  // namespace
}  // namespace boicp
