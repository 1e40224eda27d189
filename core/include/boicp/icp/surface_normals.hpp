#pragma once
// Surface normals of a fixed target cloud, estimated once per pair, for
// point-to-plane ICP.

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// Unit normal of every point of `cloud` (same order as cloud.points()): the
/// direction of least spread of its 10 nearest neighbours within `radius`
/// metres. A point with fewer than 5 such neighbours, or whose neighbours lie
/// on a line, gets the zero vector, which point-to-plane ICP ignores. The
/// sign is arbitrary. The result does not depend on `threads` (>= 1).
Points EstimateSurfaceNormals(const NearestNeighborIndex& cloud, double radius, int threads);

/// The same normal for one point `at` (usually a point of `cloud`), from its
/// 10 nearest points of `cloud` within `radius` metres; zero when they are
/// too few or lie on a line.
Point SurfaceNormalAt(const NearestNeighborIndex& cloud, const Point& at, double radius);

}  // namespace boicp
