#pragma once
// Which way is up in a map: the axis along which the map's horizontal
// surfaces (floor, tables, ceiling) face, found from the surface normals of
// its occupied cells and steered by where the sensors' own up pointed.

#include <optional>
#include <string>
#include <vector>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

struct UpDetectionOptions {
  /// The sensor's up axis in its own frame, when known: (0, -1, 0) for a
  /// depth camera (x right, y down, z forward), (0, 0, 1) for a LiDAR.
  /// With poses it gives the prior: the mean of R_map_scan * sensor_up.
  /// Without it the prior is the map's z.
  std::optional<Eigen::Vector3d> sensor_up;
  /// Radians; a plane family farther than this from the prior is not up.
  double max_prior_angle = M_PI / 4;
  /// Radians; a normal within this of an axis supports it.
  double normal_tolerance = 10.0 * M_PI / 180.0;
  /// Fraction of the cells' area that must face along the axis.
  double min_support = 0.05;
};

struct UpDirection {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // unit, map frame
  bool detected = false;  // from the map's horizontal surfaces, not a fallback
  double support = 0.0;   // fraction of the cells' area facing along `up`
  std::string reason;     // how `up` was chosen, for the user
};

/// The up axis of a sensor in its own frame, from the sensor `set` by the
/// user, else the scans' format (DeclareSensor): a depth camera has y down,
/// a LiDAR z up; other formats and sensors do not say (nullopt).
std::optional<Eigen::Vector3d> SensorUp(const std::optional<SensorKind>& set, CloudFormat format);

/// Finds the map's up direction from occupied cells (centres in the map
/// frame, metres; edge lengths `sizes`; leaf size `resolution`) and the
/// scans' poses T_map_scan (may be empty). Each cell's normal comes from
/// its neighbours within 3 leaves; the up axis is the direction, within
/// max_prior_angle of the prior, that most cell area faces along, refined
/// as the mean of those normals, with the prior's sign. When no such axis
/// has min_support, `up` is the prior if the sensors gave one, else z, and
/// `reason` says why. Deterministic; does not throw for small or empty maps.
UpDirection DetectUp(const Points& centres, const std::vector<double>& sizes, double resolution,
                     const std::vector<Transform>& poses, const UpDetectionOptions& options = {});

}  // namespace boicp
