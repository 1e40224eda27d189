#include "dataset_table.hpp"

#include <cstdio>

namespace boicp::bench {
namespace {

// Roll and pitch of a car stay within a few degrees; its yaw is unknown.
const Eigen::Vector3d kGroundVehicle(0.2, 0.2, M_PI);
// Pitch capped at pi/2: with roll and yaw over +-pi that covers SO(3) once.
const Eigen::Vector3d kAnyRotation(M_PI, M_PI / 2, M_PI);

DatasetSettings TableEntry(const std::string& name) {
  DatasetSettings s;
  s.name = name;
  if (name.rfind("kitti", 0) == 0 || name.rfind("synthetic", 0) == 0) {
    // Velodyne HDL-64E on a car (the generated street mimics it).
    s.entry = name.rfind("kitti", 0) == 0 ? "kitti" : "synthetic";
    s.perturb = PerturbationKind::kYaw;
    s.voxel = 0.6;
    s.rotation_bounds = kGroundVehicle;
    s.translation_bounds = {4.0, 2.0, 1.0};
    s.max_trans_m = 0.3;
  } else if (name.rfind("7scenes", 0) == 0) {
    // Hand-held Kinect v1: any orientation, metres of motion at most.
    s.entry = "7scenes";
    s.perturb = PerturbationKind::kAxis90;
    s.voxel = 0.05;
    s.rotation_bounds = kAnyRotation;
    s.translation_bounds = {1.0, 1.0, 1.0};
    s.max_trans_m = 0.05;
    s.depth_scale = 1000.0;
    s.intrinsics_file = "camera-intrinsics.txt";
  } else if (name.rfind("bunny", 0) == 0) {
    // Turntable range scans of a 15 cm object.
    s.entry = "bunny";
    s.perturb = PerturbationKind::kAxis90;
    s.voxel = 0.01;
    s.rotation_bounds = kAnyRotation;
    s.translation_bounds = {0.1, 0.1, 0.1};
    s.max_trans_m = 0.005;
  } else {
    s.entry = "custom";
  }
  return s;
}

}  // namespace

DatasetSettings SettingsForDataset(const std::string& folder_name,
                                   const DatasetOverrides& overrides) {
  DatasetSettings s = TableEntry(folder_name);
  if (s.entry == "custom" && (!overrides.voxel || !overrides.translation_bounds)) {
    throw UsageError("dataset '" + folder_name +
                     "' is not in the bench's table: give --voxel and --translation-bounds");
  }
  // Automatic settings are meant for data nobody has looked at, so
  // everything but a car is turned anyhow, as the real-data test does.
  if (overrides.automatic_settings && s.perturb == PerturbationKind::kAxis90)
    s.perturb = PerturbationKind::kAnyRotation;
  if (overrides.perturb) s.perturb = *overrides.perturb;
  if (overrides.max_angle_deg) s.max_angle_deg = *overrides.max_angle_deg;
  if (overrides.voxel) s.voxel = *overrides.voxel;
  if (overrides.rotation_bounds) s.rotation_bounds = *overrides.rotation_bounds;
  if (overrides.translation_bounds) s.translation_bounds = *overrides.translation_bounds;
  if (overrides.max_rot_deg) s.max_rot_deg = *overrides.max_rot_deg;
  // A custom dataset's default translation tolerance is one voxel.
  if (s.max_trans_m <= 0.0) s.max_trans_m = s.voxel;
  if (overrides.max_trans_m) s.max_trans_m = *overrides.max_trans_m;
  s.automatic_settings = overrides.automatic_settings;
  s.retry_when_doubtful = overrides.retry_when_doubtful;
  s.icp_objective = overrides.icp_objective;
  s.field = overrides.field;
  return s;
}

std::string DescribeSettings(const DatasetSettings& s) {
  char line[512];
  std::snprintf(
      line, sizeof(line),
      "%s (%s): perturb %s%s, voxel %.4g m, rotation bounds (%.3g, %.3g, %.3g) rad, "
      "translation bounds (%.3g, %.3g, %.3g) m, success < %.3g deg and < %.3g m",
      s.name.c_str(), s.entry.c_str(), PerturbationKindName(s.perturb).c_str(),
      s.perturb == PerturbationKind::kAxis90
          ? (" up to " + std::to_string(static_cast<int>(s.max_angle_deg)) + " deg").c_str()
          : "",
      s.voxel, s.rotation_bounds[0], s.rotation_bounds[1], s.rotation_bounds[2],
      s.translation_bounds[0], s.translation_bounds[1], s.translation_bounds[2], s.max_rot_deg,
      s.max_trans_m);
  std::string text = line;
  if (s.automatic_settings)
    text += "; BO methods: automatic settings (voxel and bounds above unused)";
  if (!s.retry_when_doubtful) text += "; BO methods: no retries";
  if (s.icp_objective == "point") text += "; BO methods: point-to-point ICP in the search";
  if (s.field != FieldCondition::kClean)
    text += "; field condition: " + FieldConditionName(s.field);
  if (s.depth_scale > 0.0) {
    text += ", depth PNG scale " + std::to_string(static_cast<int>(s.depth_scale)) + "/m with " +
            s.intrinsics_file;
  }
  return text;
}

}  // namespace boicp::bench
