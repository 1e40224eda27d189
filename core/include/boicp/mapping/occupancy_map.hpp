#pragma once
// Fusing registered scans into an OctoMap occupancy tree. The OctoMap types
// stay behind this interface so that users of boicp_core need no OctoMap
// headers.

#include <cstddef>
#include <functional>
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

/// Polled during long map work (ray casting, tree update, writing); true
/// ends it with boicp::Cancelled. Called from several threads at once, so it
/// must be thread-safe. Empty: never stops.
using MapStopRequest = std::function<bool()>;

/// The cells one scan marks free and occupied, ray cast but not yet applied
/// to a map. Holds memory in proportion to the cells the scan touches.
class ScanUpdate {
 public:
  ScanUpdate();
  ~ScanUpdate();
  ScanUpdate(ScanUpdate&&) noexcept;
  ScanUpdate& operator=(ScanUpdate&&) noexcept;

  size_t FreeCells() const;
  size_t OccupiedCells() const;
  /// Points left out because they lie beyond the map's key range (2^15
  /// leaves from the map origin along any axis), where OctoMap would wrap them.
  size_t PointsOutOfRange() const;
  /// Heap bytes the cells take, estimated from their count.
  size_t Bytes() const;

 private:
  friend class OccupancyMap;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class OccupancyMap {
 public:
  /// `max_tree_bytes` caps TreeBytes(): ApplyUpdate throws LimitExceeded
  /// beyond it (0 = no cap). Throws InputError for invalid settings.
  explicit OccupancyMap(const OccupancySettings& settings, size_t max_tree_bytes = 0);
  ~OccupancyMap();
  OccupancyMap(const OccupancyMap&) = delete;
  OccupancyMap& operator=(const OccupancyMap&) = delete;

  /// Inserts one scan: `points` in the scan frame, `T_map_scan` its pose and
  /// `sensor_origin` the ray origin in the scan frame. Endpoints are reduced
  /// to one per leaf before ray casting (OctoMap's discretised insertion),
  /// which keeps dense scans cheap without changing the result much.
  /// Equivalent to ApplyUpdate(ComputeUpdate(points, T_map_scan, sensor_origin, 1)).
  void InsertScan(const Points& points, const Transform& T_map_scan, const Point& sensor_origin);

  /// Ray casts one scan (arguments as for InsertScan) on `threads` threads,
  /// the calling one among them (< 1 counts as 1), without changing the map:
  /// it reads only the map's settings, so it may run while another thread
  /// applies an earlier update. The cells are the ones OctoMap's discretised
  /// insertPointCloud updates, whatever the thread count. Polls `stop` every
  /// few hundred rays and throws Cancelled once it fires. Throws
  /// LimitExceeded once the cells cast take more than `max_bytes` (0 = no
  /// limit); merging them may take as much again.
  ScanUpdate ComputeUpdate(const Points& points, const Transform& T_map_scan,
                           const Point& sensor_origin, int threads, const MapStopRequest& stop = {},
                           size_t max_bytes = 0) const;

  /// Applies an update computed by this map's ComputeUpdate: a miss for every
  /// free cell, then a hit for every occupied one. Each cell is in at most one
  /// of the two sets, so the tree does not depend on the order within a set
  /// and is bit-identical to OctoMap's own insertion of the same scan.
  /// Polls `stop` every few ten thousand cells; a Cancelled thrown from it,
  /// or a LimitExceeded once the tree passes its cap, leaves the map
  /// part-updated, fit only to be discarded.
  void ApplyUpdate(const ScanUpdate& update, const MapStopRequest& stop = {});

  /// Heap bytes the tree takes, estimated from its node count.
  size_t TreeBytes() const;

  /// Number of leaves currently believed occupied (after inner nodes are updated).
  size_t OccupiedLeaves();

  /// Writes the full-probability tree (.ot). Throws std::runtime_error on I/O
  /// failure, Cancelled when `stop` fires during the write (the file at
  /// `path` is then incomplete: write to a staging file).
  void WriteFull(const std::string& path, const MapStopRequest& stop = {});

  /// Writes the maximum-likelihood, pruned binary tree (.bt). Converts the
  /// tree in memory, so call WriteFull first when both are wanted. Throws as
  /// WriteFull does.
  void WriteBinary(const std::string& path, const MapStopRequest& stop = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace boicp
