#pragma once
// Preprocessing steps applied to a cloud before registration.

#include <cstdint>

#include "boicp/util/point_span.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// Keeps points whose distance from the sensor origin lies in [min_range,
/// max_range] metres. max_range <= 0 means no upper limit.
Points CropByRange(PointSpan points, double min_range, double max_range);

/// The order in which VoxelDownsample returns its cells.
enum class CellOrder {
  /// The order in which the cloud first reaches each cell: a scan's
  /// neighbouring cells stay near each other in memory.
  kFirstReached,
  /// Open3D's hash-map order. The fixed budget's answers depend on it through
  /// their seeded subsamples, and keep them.
  kOpen3d,
};

/// Replaces the points in each cubic voxel of edge `voxel` metres by their
/// centroid: the points of Open3D's VoxelDownSample, bit for bit, in `order`.
/// voxel <= 0 returns the input unchanged. Throws InputError when the cloud
/// spans more cells than an int counts.
Points VoxelDownsample(const Points& points, double voxel,
                       CellOrder order = CellOrder::kFirstReached);

/// At most `max_points` points chosen uniformly without replacement, in their
/// original order; reproducible for a given seed. max_points == 0 or
/// max_points >= size returns the input unchanged.
Points RandomSubsample(PointSpan points, size_t max_points, uint64_t seed);

/// Mean of the points (zero for an empty input).
Point Centroid(const Points& points);

/// Root-mean-square distance of the points from their centroid, in their
/// units (zero for an empty input).
double RmsRadius(const Points& points);

}  // namespace boicp
