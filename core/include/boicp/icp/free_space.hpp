#pragma once
// Whether an alignment puts one scan's surfaces where the other scan's
// sensor saw through. A wrong basin of a self-similar scene (a street turned
// half round, a corridor shifted along itself) can match as many points as
// the right one, but it moves surfaces into space the other sensor looked
// across; the right one does not, except for what moved between the scans.

#include <vector>

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// What a sensor saw: in every cell of directions about it (about 1 degree
/// across), the range of its nearest return.
class RangeImage {
 public:
  /// `points` and `sensor` in one frame, metres.
  RangeImage(const Points& points, const Point& sensor);

  /// Cells holding a return. An image of a few cells says little: the frame's
  /// origin is then far from the points, or not where a sensor stood.
  size_t covered_cells() const { return covered_; }

  /// The sensor's position, metres.
  const Point& sensor() const { return sensor_; }

  /// The nearest return's range in the direction of `p` (metres, the
  /// image's frame); infinity where the sensor returned nothing.
  double NearestReturn(const Point& p) const;

 private:
  Point sensor_;
  std::vector<float> nearest_;  // per cell; infinity when empty
  size_t covered_ = 0;
};

/// Share of `source` points that `T` (T_target_source) moves into space the
/// target's sensor saw through: nearer to it than its nearest return in
/// their direction, by more than max(`margin`, 5 % of that return's range),
/// and farther than `inlier_distance` from every `target` point (so the
/// target's own surfaces, sampled within a cell at other ranges, are not
/// counted). Counted among the points in directions the target returned
/// from; 0 when there are none. Preconditions: `view` is the target's
/// RangeImage; margin, inlier_distance > 0 metres.
double SeenThroughShare(const Points& source, const NearestNeighborIndex& target,
                        const RangeImage& view, const Transform& T, double margin,
                        double inlier_distance);

}  // namespace boicp
