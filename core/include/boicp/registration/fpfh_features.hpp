#pragma once
// Fast Point Feature Histograms (Rusu, Blodow & Beetz, ICRA 2009): a local
// shape descriptor per point that does not change when the cloud is rotated,
// so two clouds can be matched point to point before any pose is known.

#include <cstddef>

#include <Eigen/Core>

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// 33-bin FPFH descriptors (Rusu et al. 2009), one column per point.
using FpfhFeatures = Eigen::Matrix<float, 33, Eigen::Dynamic>;

/// Neighbours a point's histogram takes at most, by default.
constexpr size_t kMaxFpfhNeighbours = 100;

/// FPFH of every point of `cloud` from its neighbours within `radius` metres (at most
/// `max_neighbours` of them, nearest first) and `normals` (same order as cloud.points();
/// a zero normal, as EstimateSurfaceNormals gives a point it cannot fit, contributes nothing).
/// Does not depend on `threads` (>= 1).
///
/// Each of the three 11-bin blocks of a column (the angle between the normals
/// about the Darboux frame, then the two direction cosines) sums to 100, or is
/// all zero when no two points with normals are within reach. Normal signs are
/// arbitrary out of EstimateSurfaceNormals, so each normal is first turned to
/// face `viewpoint` (metres, in the cloud's frame): where the sensor stood, so
/// that two views of one surface give its normals the same sign. Descriptors
/// are then invariant to rotations of a scan about its sensor. Throws
/// InputError unless normals.size() == cloud.size(), radius > 0 and
/// max_neighbours >= 1.
FpfhFeatures ComputeFpfhFeatures(const NearestNeighborIndex& cloud, const Points& normals,
                                 double radius, int threads,
                                 size_t max_neighbours = kMaxFpfhNeighbours,
                                 const Point& viewpoint = Point::Zero());

}  // namespace boicp
