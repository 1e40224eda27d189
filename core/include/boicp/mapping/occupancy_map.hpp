#pragma once
// Fusing registered scans into an OctoMap occupancy tree. The OctoMap types
// stay behind this interface so that users of boicp_core need no OctoMap
// headers.

#include <cstddef>
#include <memory>
#include <string>

#include "boicp/util/types.hpp"

namespace boicp {

/// OctoMap resolution, ray length and sensor model. The probability defaults
/// are octomap_server's.
struct OccupancySettings {
  double resolution = 0.2;  // metres, leaf size
  double max_range =
      0.0;  // metres; rays are cut here and farther endpoints not marked; 0 = no limit
  double prob_hit = 0.7;    // in (0.5, 1)
  double prob_miss = 0.4;   // in (0, 0.5)
  double clamp_min = 0.12;  // in (0, 1), below clamp_max
  double clamp_max = 0.97;
};

/// Throws InputError naming the first invalid field.
void ValidateOccupancySettings(const OccupancySettings& settings);

class OccupancyMap {
 public:
  /// Throws InputError for invalid settings.
  explicit OccupancyMap(const OccupancySettings& settings);
  ~OccupancyMap();
  OccupancyMap(const OccupancyMap&) = delete;
  OccupancyMap& operator=(const OccupancyMap&) = delete;

  /// Inserts one scan: `points` in the scan frame, `T_map_scan` its pose and
  /// `sensor_origin` the ray origin in the scan frame. Endpoints are reduced
  /// to one per leaf before ray casting (OctoMap's discretised insertion),
  /// which keeps dense scans cheap without changing the result much.
  void InsertScan(const Points& points, const Transform& T_map_scan, const Point& sensor_origin);

  /// Number of leaves currently believed occupied (after inner nodes are updated).
  size_t OccupiedLeaves();

  /// Writes the full-probability tree (.ot). Throws std::runtime_error on I/O failure.
  void WriteFull(const std::string& path);

  /// Writes the maximum-likelihood, pruned binary tree (.bt). Converts the
  /// tree in memory, so call WriteFull first when both are wanted. Throws
  /// std::runtime_error on I/O failure.
  void WriteBinary(const std::string& path);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace boicp
