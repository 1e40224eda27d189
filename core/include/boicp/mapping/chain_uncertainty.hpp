#pragma once
// How far a chain of registered pairs may have drifted between two of its
// scans: the covariance of the relative pose its spanning tree gives them,
// composed to first order from each tree edge's covariance. A loop closure
// is expected to disagree with the chain by about that much.

#include <vector>

#include <Eigen/Core>

#include "boicp/mapping/pose_graph.hpp"

namespace boicp {

/// 6 x 6, rotation first, then translation (radians, metres): the
/// covariance of a small motion xi applied on the right, T * exp(xi).
using PoseCovariance = Eigen::Matrix<double, 6, 6>;

/// The adjoint of `T` in that order: T * exp(xi) * T^-1 = exp(Adjoint(T) * xi).
Eigen::Matrix<double, 6, 6> Adjoint(const Transform& T);

/// The misfit of `constraint` under `poses` (T_map_scan): the small motion
/// xi, rotation vector first, with T_target_source * exp(xi) =
/// poses[target]^-1 * poses[source]. Preconditions: both indices in `poses`.
Eigen::Matrix<double, 6, 1> ConstraintMisfit(const PairConstraint& constraint,
                                             const std::vector<Transform>& poses);

class ChainUncertainty {
 public:
  /// `poses` chained along the tree edges (`in_tree`) of `constraints`;
  /// each edge's covariance is the inverse of its information, which must
  /// be weighted as the optimisation weighs it. Throws InputError when the
  /// tree edges leave a scan unreached from scan 0.
  ChainUncertainty(const std::vector<Transform>& poses,
                   const std::vector<PairConstraint>& constraints,
                   const std::vector<bool>& in_tree);

  /// The covariance of poses[a]^-1 * poses[b] along the tree's path from
  /// scan a to scan b. Preconditions: a and b are scans of the chain.
  PoseCovariance Between(int a, int b) const;

  /// The chi-square (6 degrees of freedom) of `loop`'s misfit under the
  /// chain's covariance between its scans plus its own (the inverse of its
  /// information): about 6 for a right loop on a chain whose edge
  /// covariances are calibrated, far more for a wrong one.
  double LoopDisagreement(const PairConstraint& loop) const;

 private:
  // The covariance of poses[ancestor]^-1 * poses[scan], composed down the tree.
  PoseCovariance FromAncestor(int ancestor, int scan) const;

  std::vector<Transform> poses_;
  std::vector<int> parent_;           // -1 at scan 0
  std::vector<int> depth_;            // tree edges from scan 0
  std::vector<PoseCovariance> step_;  // of poses[parent]^-1 * poses[scan]
};

}  // namespace boicp
