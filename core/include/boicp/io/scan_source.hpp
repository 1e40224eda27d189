#pragma once
// One scan of a batch: where its points are, how to read them, and what is
// known of where it was taken. Folders, uploads and the map pipeline all
// describe scans this way.

#include <optional>
#include <string>
#include <vector>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

struct ScanSource {
  std::string path;  // file to load
  LoadOptions load;  // format (explicit, or from the extension) and depth options
  Point sensor_origin = Point::Zero();  // ray origin in the scan frame, metres
  std::optional<Transform> prior_pose;  // odometry T_world_scan, when known
  std::optional<double> timestamp;      // seconds, when known
};

/// Prior for registering `source` onto `target` from their prior poses:
/// T_target_source = T_world_target^-1 * T_world_source; nullopt unless both have one.
std::optional<Transform> PairPrior(const ScanSource& source, const ScanSource& target);

/// Each scan's timestamp, or its index where it has none.
std::vector<double> ScanTimestamps(const std::vector<ScanSource>& scans);

}  // namespace boicp
