#pragma once
// How firmly a registered pair's point correspondences pin down its
// transform: the information matrix a pose graph weighs the pair's edge by.

#include <Eigen/Core>

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// 6 x 6, rotation first, then translation (Open3D's pose-graph convention).
using InformationMatrix = Eigen::Matrix<double, 6, 6>;

/// The sum of J^T J over the target points q matched within `max_distance`
/// metres by the source points moved by T_target_source, with
/// J = n^T [-[q]x | I]: how far the match moves off its surface under a
/// small rotation and translation, n being the target's surface normal at q
/// (SurfaceNormalAt, within `normal_radius` metres). A direction no surface
/// faces (along a wall, a corridor, a floor) gets no information: the
/// geometry does not constrain it. The trace of the translation block
/// counts the matches with a normal; zero when nothing matches. The cost is
/// two nearest-neighbour searches per source point.
InformationMatrix PlaneInformation(const Points& source, const NearestNeighborIndex& target,
                                   const Transform& T_target_source, double max_distance,
                                   double normal_radius);

/// The information of the same matches with every target point moved by
/// `offset` metres (q + offset): A^T * information * A with
/// A = [I 0; -[offset]x I], exactly what PlaneInformation gives on the
/// moved points. It carries an answer found on centred clouds back to the scans'
/// frames.
InformationMatrix MovedInformation(const InformationMatrix& information, const Point& offset);

}  // namespace boicp
