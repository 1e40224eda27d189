#pragma once
// Per-dataset benchmark settings, keyed by the folder that holds pairs.csv.
// These are inputs of the benchmark (sensor scale, motion model, what counts
// as success), never results.

#include <string>

#include <Eigen/Core>

#include "bench_options.hpp"
#include "evaluation.hpp"

namespace boicp::bench {

struct DatasetSettings {
  std::string name;   // folder name of the pairs.csv ("kitti00", ...)
  std::string entry;  // table entry it matched ("kitti", "7scenes", "bunny", "synthetic")
  PerturbationKind perturb = PerturbationKind::kAxis90;
  double max_angle_deg = 90.0;  // axis perturbation: angle uniform in [0, this]
  double voxel = 0.0;           // metres: search voxel of every method (bo-A/B scale it)
  Eigen::Vector3d rotation_bounds{M_PI, M_PI / 2, M_PI};  // radians (roll, pitch, yaw)
  Eigen::Vector3d translation_bounds{0.0, 0.0, 0.0};      // metres; also the perturbation's
  double max_rot_deg = 2.0;                               // success thresholds
  double max_trans_m = 0.0;
  double depth_scale = 0.0;         // > 0: clouds are depth PNGs with this many units per metre
  std::string intrinsics_file;      // depth PNGs: camera file, relative to the folder
  bool automatic_settings = false;  // BO methods ignore voxel and bounds and choose their own
  bool retry_when_doubtful = true;
  std::string icp_objective = "plane";            // BO methods' search evaluations
  FieldCondition field = FieldCondition::kClean;  // what is done to the loaded scans
};

/// The table entry for `folder_name` (matched by prefix: "kitti", "7scenes",
/// "bunny", "synthetic") with `overrides` applied. A folder with no entry
/// needs --voxel and --translation-bounds; otherwise throws UsageError.
DatasetSettings SettingsForDataset(const std::string& folder_name,
                                   const DatasetOverrides& overrides);

/// One line describing the settings, for summary.md and the printed header.
std::string DescribeSettings(const DatasetSettings& settings);

}  // namespace boicp::bench
