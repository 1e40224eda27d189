#pragma once
// Point-to-point ICP (Besl & McKay) against a prebuilt target index.

#include "boicp/nearest_neighbors.hpp"
#include "boicp/types.hpp"

namespace boicp {

struct IcpOptions {
  double max_correspondence_distance = 1.0;  // metres; pairs farther apart are ignored
  int max_iterations = 30;
  double convergence_translation = 1e-4;  // metres: stop once a step moves less than this...
  double convergence_rotation = 1e-4;     // ...and rotates less than this (radians)
  int threads = 1;  // for the nearest-neighbour searches; results do not depend on it
};

/// Outcome of one ICP run. `transform` is T_target_source: p_target = T * p_source.
struct IcpResult {
  Transform transform = Transform::Identity();
  int iterations = 0;
  bool converged = false;      // the step criterion was met before max_iterations
  size_t correspondences = 0;  // in the last iteration
  double rmse = 0.0;           // of the last iteration's correspondences, metres
};

/// Rigid transform that best maps the `source` points onto their paired
/// `target` points in the least-squares sense (Kabsch / Umeyama without scale),
/// from the sums of one iteration. Precondition: count >= 3, not collinear.
Transform RigidFromCrossCovariance(const Point& source_mean, const Point& target_mean,
                                   const Eigen::Matrix3d& cross_covariance);

/// Runs ICP from `initial`. Allocates its scratch buffers once per call, never
/// per iteration. With fewer than 3 correspondences it stops and returns the
/// last transform with converged = false.
IcpResult AlignPointToPoint(const Points& source, const NearestNeighborIndex& target,
                            const Transform& initial, const IcpOptions& options);

}  // namespace boicp
