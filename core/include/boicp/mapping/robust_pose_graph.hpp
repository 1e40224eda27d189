#pragma once
// Pose-graph optimisation under a robust loss (Ceres): every edge's squared
// Mahalanobis misfit goes through a Cauchy loss, so an edge that disagrees
// with the rest far beyond its uncertainty (a pair that slid along a wall,
// a wrong loop closure) gives way instead of bending everything else.

#include <vector>

#include "boicp/mapping/pose_graph.hpp"

namespace boicp {

struct RobustPoseGraphOptions {
  /// The squared Mahalanobis misfit at which an edge's weight halves (the
  /// Cauchy loss's scale b: weight 1 / (1 + e^T I e / b)).
  double loss_scale = kLoopAgreementChi2;
  int max_iterations = 100;
};

struct RobustPoseGraphSolution {
  std::vector<Transform> poses;  // T_map_scan; scan 0 as given
  /// Per edge: its weight under the loss at the solution, in (0, 1]
  /// (1 = it agrees with the others exactly).
  std::vector<double> weights;
};

/// Poses minimising the sum over `edges` of the Cauchy loss of e^T I e,
/// e = ConstraintMisfit(edge, poses) and I its information (used as
/// given: scale it first for confidence). Scan 0 stays at initial[0].
/// Preconditions: every edge's scans are in `initial`, every information
/// positive definite. Deterministic (one thread).
RobustPoseGraphSolution SolveRobustPoseGraph(const std::vector<Transform>& initial,
                                             const std::vector<PairConstraint>& edges,
                                             const RobustPoseGraphOptions& options = {});

}  // namespace boicp
