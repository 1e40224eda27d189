#include "boicp/mapping/chain_uncertainty.hpp"

#include <string>

#include <Eigen/Geometry>
#include <Eigen/LU>

namespace boicp {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// The inverse of an information matrix, regularised so that a direction the
// inliers leave free gets a large variance instead of an infinite one.
PoseCovariance CovarianceOf(const InformationMatrix& information) {
  const double scale = std::max(information.diagonal().maxCoeff(), 1e-300);
  return (information + InformationMatrix::Identity() * (1e-9 * scale)).inverse();
}

// The covariance of T^-1 for T perturbed on the right with `covariance`:
// (T exp(xi))^-1 = T^-1 exp(-Adjoint(T) xi).
PoseCovariance OfInverse(const Transform& T, const PoseCovariance& covariance) {
  const Eigen::Matrix<double, 6, 6> ad = Adjoint(T);
  return ad * covariance * ad.transpose();
}

// The covariance of A * B given those of A and B, independent:
// A exp(a) B exp(b) = A B exp(Adjoint(B^-1) a + b).
PoseCovariance OfProduct(const PoseCovariance& a, const Transform& B, const PoseCovariance& b) {
  const Eigen::Matrix<double, 6, 6> ad = Adjoint(B.inverse());
  return ad * a * ad.transpose() + b;
}

}  // namespace

Eigen::Matrix<double, 6, 6> Adjoint(const Transform& T) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  Eigen::Matrix<double, 6, 6> ad = Eigen::Matrix<double, 6, 6>::Zero();
  ad.topLeftCorner<3, 3>() = R;
  ad.bottomRightCorner<3, 3>() = R;
  ad.bottomLeftCorner<3, 3>() = Skew(T.topRightCorner<3, 1>()) * R;
  return ad;
}

Eigen::Matrix<double, 6, 1> ConstraintMisfit(const PairConstraint& constraint,
                                             const std::vector<Transform>& poses) {
  const Transform misfit = constraint.T_target_source.inverse() *
                           poses[static_cast<size_t>(constraint.pair.target)].inverse() *
                           poses[static_cast<size_t>(constraint.pair.source)];
  const Eigen::AngleAxisd rotation(Eigen::Matrix3d(misfit.topLeftCorner<3, 3>()));
  Eigen::Matrix<double, 6, 1> xi;
  xi << rotation.angle() * rotation.axis(), misfit.topRightCorner<3, 1>();
  return xi;
}

ChainUncertainty::ChainUncertainty(const std::vector<Transform>& poses,
                                   const std::vector<PairConstraint>& constraints,
                                   const std::vector<bool>& in_tree)
    : poses_(poses),
      parent_(poses.size(), -1),
      depth_(poses.size(), -1),
      step_(poses.size(), PoseCovariance::Zero()) {
  if (poses.empty()) return;
  depth_[0] = 0;
  for (const TreeStep& step : WalkTree(static_cast<int>(poses.size()), constraints, in_tree)) {
    const PairConstraint& c = constraints[step.edge];
    const auto n = static_cast<size_t>(step.scan);
    parent_[n] = step.from;
    depth_[n] = depth_[static_cast<size_t>(step.from)] + 1;
    // The edge measures T_target_source, perturbed on the right.
    const PoseCovariance edge = CovarianceOf(c.information);
    step_[n] = c.pair.target == step.from ? edge : OfInverse(c.T_target_source, edge);
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    if (depth_[i] < 0) {
      throw InputError("chain uncertainty: no tree edge reaches scan " + std::to_string(i));
    }
  }
}

PoseCovariance ChainUncertainty::FromAncestor(int ancestor, int scan) const {
  std::vector<int> path;  // scan up to, not including, the ancestor
  for (int at = scan; at != ancestor; at = parent_[static_cast<size_t>(at)]) path.push_back(at);
  PoseCovariance covariance = PoseCovariance::Zero();
  for (auto it = path.rbegin(); it != path.rend(); ++it) {
    const auto child = static_cast<size_t>(*it);
    const auto parent = static_cast<size_t>(parent_[child]);
    covariance =
        OfProduct(covariance, Transform(poses_[parent].inverse() * poses_[child]), step_[child]);
  }
  return covariance;
}

PoseCovariance ChainUncertainty::Between(int a, int b) const {
  int x = a, y = b;
  while (depth_[static_cast<size_t>(x)] > depth_[static_cast<size_t>(y)]) {
    x = parent_[static_cast<size_t>(x)];
  }
  while (depth_[static_cast<size_t>(y)] > depth_[static_cast<size_t>(x)]) {
    y = parent_[static_cast<size_t>(y)];
  }
  while (x != y) {
    x = parent_[static_cast<size_t>(x)];
    y = parent_[static_cast<size_t>(y)];
  }
  const int common = x;
  const auto c = static_cast<size_t>(common);
  const Transform to_a = poses_[c].inverse() * poses_[static_cast<size_t>(a)];
  const Transform to_b = poses_[c].inverse() * poses_[static_cast<size_t>(b)];
  return OfProduct(OfInverse(to_a, FromAncestor(common, a)), to_b, FromAncestor(common, b));
}

double ChainUncertainty::LoopDisagreement(const PairConstraint& loop) const {
  const Eigen::Matrix<double, 6, 1> misfit = ConstraintMisfit(loop, poses_);
  const PoseCovariance total =
      Between(loop.pair.target, loop.pair.source) + CovarianceOf(loop.information);
  return misfit.dot(total.ldlt().solve(misfit));
}

}  // namespace boicp
