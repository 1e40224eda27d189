#pragma once
// Settings chosen from the clouds themselves, so that a folder of scans needs
// no per-dataset flags: the search scale, the search box and the map's
// resolution follow the scene's size, and the rotation box follows the
// sensor (a level LiDAR only turns about z; anything else may turn anyhow).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/util/point_span.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// What is known of the sensor before any geometry is measured.
struct DeclaredSensor {
  SensorKind kind = SensorKind::kOther;
  std::string why;  // "set by --sensor", "KITTI .bin scans (a spinning LiDAR)", "depth images"
};

/// The user's --sensor (`set`), else what `format` implies: KITTI .bin scans
/// come from a spinning LiDAR, depth images from a depth camera. nullopt when
/// neither says, and the geometry decides.
std::optional<DeclaredSensor> DeclareSensor(const std::optional<SensorKind>& set,
                                            CloudFormat format);

/// What the settings are chosen from, measured on one cloud in its sensor frame.
struct CloudStatistics {
  size_t points = 0;
  /// Points set aside as far returns (beyond 12 median distances from the
  /// median point) before every statistic below; 0 on a clean scan.
  size_t far_returns = 0;
  double rms_radius = 0.0;  // RMS distance from the centroid, metres
  double range_p95 = 0.0;   // 95th percentile of the distance from the sensor origin, metres
  double spacing = 0.0;     // median distance from a point to its nearest other point, metres
  /// Points on most sides of the origin (a spinning LiDAR, also with a
  /// sector blocked): directions that do not share one cone (mean_direction
  /// at most 0.5) over at least 240 degrees of azimuth.
  bool all_around = false;
  double azimuth_coverage_deg = 0.0;  // azimuth about z holding points, in 10-degree sectors
  double mean_direction = 0.0;        // norm of the mean unit direction from the origin, [0, 1]
  /// Angle (radians) between +z and the normal of a ground plane below the
  /// origin that holds a large share of the points; nullopt when none is found.
  std::optional<double> ground_tilt;
  double ground_depth = 0.0;  // metres from the origin down to that plane (0 without one)
};

/// Measures `cloud` (metres, sensor frame). Random choices use `seed`.
/// Throws InputError when the cloud has fewer than kMinPointsForSettings
/// points or no extent, with a message that names the flags to give instead.
CloudStatistics MeasureCloud(PointSpan cloud, uint64_t seed);

constexpr size_t kMinPointsForSettings = 100;

/// Every setting automatic mode chooses, with the sensor it assumed.
struct ChosenSettings {
  SensorKind sensor = SensorKind::kOther;
  /// Why, for the user: "ring covering 350 deg, ground plane 1.73 m below
  /// the origin", "one-sided view (mean direction 0.83)", ...
  std::string sensor_reason;
  double voxel = 0.0;          // metres, search voxel for preset C (truncation follows it)
  double point_spacing = 0.0;  // metres; with the voxel, sets the refinement voxel
  Eigen::Vector3d translation_bounds = Eigen::Vector3d::Zero();  // metres
  Eigen::Vector3d rotation_bounds = Eigen::Vector3d::Zero();     // radians
  double map_resolution = 0.0;                                   // metres
  double map_max_range = 0.0;                                    // metres
  std::vector<size_t> far_returns;  // set aside in each measured cloud, in order
};

/// The settings for clouds measured by `stats` (at least one), from the
/// `declared` sensor (DeclareSensor), else the one the geometry shows.
/// Throws InputError, naming both scales, when a cloud's RMS radius and point
/// spacing both differ from the first cloud's by more than 20 times (a
/// millimetre cloud against a metre one).
ChosenSettings ChooseSettings(const std::vector<CloudStatistics>& stats,
                              const std::optional<DeclaredSensor>& declared);

/// Measures up to `max_clouds` of `clouds`, evenly spread (a batch's settings
/// come from a few scans, so that every pair of it shares them), and chooses;
/// the clouds are measured on up to `threads` threads at once, which does not
/// change the choice.
ChosenSettings ChooseSettingsForClouds(const std::vector<PointSpan>& clouds,
                                       const std::optional<DeclaredSensor>& declared, uint64_t seed,
                                       size_t max_clouds = 5, int threads = 1);

/// Copies the chosen values into the fields of `config` still listed in
/// config.automatic (the voxel scaled as the preset's is against C's) and
/// clears that list. Returns the names of the fields it set, in
/// kAutoRegistrationFields order.
std::vector<std::string> ApplyChosenSettings(const ChosenSettings& chosen, BoIcpConfig& config);

/// Chooses the fields still in config.automatic from a pair's two raw clouds
/// (the sensor as config.sensor says, else from their geometry), as
/// RegisterPair does, and returns their names (ApplyChosenSettings). Throws
/// InputError for clouds too small to choose from.
std::vector<std::string> ChooseSettingsForPair(PointSpan source, PointSpan target,
                                               BoIcpConfig& config);

/// One line for the user: preset, search mode, the sensor and why, and the
/// voxel, refinement voxel and boxes, each marked "(auto)" when in
/// `auto_fields`.
std::string DescribeSettings(const BoIcpConfig& config, const std::vector<std::string>& auto_fields,
                             const ChosenSettings& chosen);

}  // namespace boicp
