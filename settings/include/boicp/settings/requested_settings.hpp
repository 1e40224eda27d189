#pragma once
// The registration and map settings as a user gives them, through any front
// end (flags, run.json, a SubmitBatchRequest), before a preset fills in the
// rest. setting_schema.hpp names every field for each front end.

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/map_assembly.hpp"
#include "boicp/registration/config.hpp"

namespace boicp::settings {

/// Unset optionals keep the preset's value, or are chosen from the scans
/// when BoIcpConfig::automatic (or MapAutoFields) lists them.
struct RequestedSettings {
  // --- Registration --------------------------------------------------------
  std::string method = kDefaultMethod;  // a name in CoreMethods(): bo-icp | icp
  std::string preset = "C";             // the paper's A, B or C (case-insensitive)
  std::string mode = "nested";          // nested | 6dof
  std::string icp_objective = "plane";  // plane | point: the search evaluations' ICP
  std::string budget = "auto";          // auto (the escalation ladder) | fixed (the full search)
  std::string sensor = "auto";          // lidar | depth | object | auto (format, then geometry)
  uint64_t seed = 1;                    // job seed; each pair's seed derives from it
  bool fixed_settings = false;          // the preset's fixed voxel, bounds and map settings
  bool no_retry = false;                // never search a doubtful pair again
  std::optional<double> voxel;          // search voxel, metres
  std::optional<int> random_samples;    // N_r per search stage
  std::optional<int> iterations;        // N per search stage
  std::optional<Eigen::Vector3d> rotation_bounds;     // half-widths roll, pitch, yaw; radians
  std::optional<Eigen::Vector3d> translation_bounds;  // half-widths x, y, z; metres
  std::optional<uint64_t> evaluation_points;          // source points per evaluation; 0 = all
  std::optional<double> refine_voxel;                 // metres
  std::optional<double> max_correspondence;           // ICP gate of the search, metres
  std::optional<double> min_range;                    // metres from the sensor
  std::optional<double> scan_max_range;               // metres from the sensor; 0 = no limit
  std::optional<double> objective_truncation;         // metres
  std::optional<int> icp_iterations;                  // ICP iterations per evaluation
  std::optional<uint64_t> coarse_icp_points;          // 0 = the whole run on all points
  std::optional<int> threads;                         // threads inside one registration

  // --- Map (OctoMap fusion) --------------------------------------------------
  std::optional<double> resolution;                                 // leaf size, metres
  std::optional<double> max_range;                                  // ray cut, metres; 0 = no limit
  std::optional<double> prob_hit, prob_miss, clamp_min, clamp_max;  // sensor model
  std::optional<double> cloud_voxel;          // merged PLY voxel, metres; 0 = resolution
  std::string loops = "auto";                 // auto | off: loop closures found by the map itself
  std::string untrusted_scans = "leave-out";  // leave-out | place: scans with no trusted pair
};

/// The preset with every given registration setting applied (a given
/// setting is marked set, so it is never chosen from the clouds), validated.
/// Throws InputError naming the field.
BoIcpConfig ConfigFromSettings(const RequestedSettings& settings);

/// Every registration setting of `config` as used: derived values ("0 =
/// auto") resolved, `fixed_settings` false.
RequestedSettings SettingsFromConfig(const BoIcpConfig& config);

/// OccupancySettings' defaults with the given map settings applied,
/// validated. Throws InputError naming the field.
MapBuildSettings MapBuildFromSettings(const RequestedSettings& settings);

/// Which map settings are still to be chosen from the scans.
MapAutoFields MapAutoFromSettings(const RequestedSettings& settings);

}  // namespace boicp::settings
