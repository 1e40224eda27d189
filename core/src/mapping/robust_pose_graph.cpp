#include "boicp/mapping/robust_pose_graph.hpp"

#include <memory>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "boicp/mapping/chain_uncertainty.hpp"

namespace boicp {
namespace {

// One pose as Ceres moves it: a unit quaternion (x, y, z, w) and a translation.
struct PoseBlock {
  Eigen::Quaterniond rotation;
  Eigen::Vector3d translation;
};

// The misfit of T_target_source (ConstraintMisfit, with the rotation vector
// taken to first order as twice the quaternion's vector part), whitened by
// the square root of the edge's information.
class EdgeMisfit {
 public:
  EdgeMisfit(const Transform& T_target_source, const InformationMatrix& information)
      : rotation_(Eigen::Matrix3d(T_target_source.topLeftCorner<3, 3>())),
        translation_(T_target_source.topRightCorner<3, 1>()),
        whitening_(information.llt().matrixU()) {}

  template <typename T>
  bool operator()(const T* source_q, const T* source_t, const T* target_q, const T* target_t,
                  T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_source(source_q), q_target(target_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_source(source_t), t_target(target_t);
    // T_target^-1 * T_source, then the measurement's inverse applied.
    const Eigen::Quaternion<T> q_relative = q_target.conjugate() * q_source;
    const Eigen::Matrix<T, 3, 1> t_relative = q_target.conjugate() * (t_source - t_target);
    const Eigen::Quaternion<T> q_measured = rotation_.cast<T>();
    Eigen::Quaternion<T> q_misfit = q_measured.conjugate() * q_relative;
    if (q_misfit.w() < T(0)) q_misfit.coeffs() *= T(-1);
    Eigen::Matrix<T, 6, 1> misfit;
    misfit << T(2) * q_misfit.vec(), q_measured.conjugate() * (t_relative - translation_.cast<T>());
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = whitening_.cast<T>() * misfit;
    return true;
  }

 private:
  Eigen::Quaterniond rotation_;
  Eigen::Vector3d translation_;
  Eigen::Matrix<double, 6, 6> whitening_;  // U with U^T U = information
};

Transform ToTransform(const PoseBlock& block) {
  Transform T = Transform::Identity();
  T.topLeftCorner<3, 3>() = block.rotation.normalized().toRotationMatrix();
  T.topRightCorner<3, 1>() = block.translation;
  return T;
}

}  // namespace

RobustPoseGraphSolution SolveRobustPoseGraph(const std::vector<Transform>& initial,
                                             const std::vector<PairConstraint>& edges,
                                             const RobustPoseGraphOptions& options) {
  std::vector<PoseBlock> blocks;
  blocks.reserve(initial.size());
  for (const Transform& pose : initial) {
    blocks.push_back({Eigen::Quaterniond(Eigen::Matrix3d(pose.topLeftCorner<3, 3>())),
                      pose.topRightCorner<3, 1>()});
  }
  ceres::Problem problem;
  for (const PairConstraint& edge : edges) {
    PoseBlock& source = blocks[static_cast<size_t>(edge.pair.source)];
    PoseBlock& target = blocks[static_cast<size_t>(edge.pair.target)];
    auto* cost = new ceres::AutoDiffCostFunction<EdgeMisfit, 6, 4, 3, 4, 3>(
        new EdgeMisfit(edge.T_target_source, edge.information));
    problem.AddResidualBlock(cost, new ceres::CauchyLoss(std::sqrt(options.loss_scale)),
                             source.rotation.coeffs().data(), source.translation.data(),
                             target.rotation.coeffs().data(), target.translation.data());
  }
  for (PoseBlock& block : blocks) {
    if (!problem.HasParameterBlock(block.rotation.coeffs().data())) continue;
    problem.SetManifold(block.rotation.coeffs().data(), new ceres::EigenQuaternionManifold());
  }
  if (!blocks.empty() && problem.HasParameterBlock(blocks[0].rotation.coeffs().data())) {
    problem.SetParameterBlockConstant(blocks[0].rotation.coeffs().data());
    problem.SetParameterBlockConstant(blocks[0].translation.data());
  }

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  RobustPoseGraphSolution solution;
  solution.poses = initial;
  for (size_t i = 1; i < blocks.size(); ++i) solution.poses[i] = ToTransform(blocks[i]);
  for (const PairConstraint& edge : edges) {
    const Eigen::Matrix<double, 6, 1> misfit = ConstraintMisfit(edge, solution.poses);
    solution.weights.push_back(1.0 /
                               (1.0 + misfit.dot(edge.information * misfit) / options.loss_scale));
  }
  return solution;
}

}  // namespace boicp
