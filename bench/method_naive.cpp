// naive: the straightforward port of BO-ICP (config C on the dataset). Same
// stages, seeds, subsampling, search boxes and objective as core's
// RegisterPair, but every evaluation calls Open3D's RegistrationICP afresh,
// which rebuilds the target kd-tree, and scores with a fresh KDTreeFlann.
// Every speed change is measured against this in the same run.

#include <algorithm>
#include <cmath>
#include <vector>

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>

#include "boicp/bayes_opt.hpp"
#include "boicp/preprocess.hpp"
#include "boicp/search_space.hpp"
#include "methods.hpp"
#include "shared_stages.hpp"

namespace boicp::bench {
namespace {

namespace reg = open3d::pipelines::registration;
using open3d::geometry::PointCloud;

// The salts of core's bo_icp.cpp, so the port draws the same subsample and
// the same Latin hypercubes as bo-C.
constexpr uint64_t kSubsampleSalt = 0x9e3779b97f4a7c15ULL;
constexpr uint64_t kStageSalt = 0xbf58476d1ce4e5b9ULL;

Points Prepare(const Points& raw, const BoIcpConfig& config, double voxel) {
  Points sampled = VoxelDownsample(CropByRange(raw, config.min_range, config.max_range), voxel);
  if (sampled.size() < 3) throw InputError("naive: a cloud has fewer than 3 points left");
  return sampled;
}

// (1/n) sum min(d_i, tau) over source points moved by T.
double TruncatedMean(const PointCloud& source, const PointCloud& target, const Transform& T,
                     double tau, int threads) {
  const open3d::geometry::KDTreeFlann tree(target);  // fresh on purpose: the naive cost
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  std::vector<double> clipped(source.points_.size());
  const auto n = static_cast<long>(clipped.size());
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
  for (long i = 0; i < n; ++i) {
    std::vector<int> index(1);
    std::vector<double> sq_distance(1);
    const bool found =
        tree.SearchKNN<Eigen::Vector3d>(R * source.points_[i] + t, 1, index, sq_distance) > 0;
    clipped[i] = found ? std::min(std::sqrt(sq_distance[0]), tau) : tau;
  }
  double sum = 0.0;
  for (double d : clipped) sum += d;
  return sum / static_cast<double>(std::max<size_t>(clipped.size(), 1));
}

struct NaiveEvaluation {
  Transform result = Transform::Identity();
  double objective = 0.0;
};

class NaiveSearch {
 public:
  NaiveSearch(const PointCloud& source, const PointCloud& target, const BoIcpConfig& config)
      : source_(source), target_(target), config_(config) {}

  BayesOptResult RunStage(int stage, const SearchSpace& space) {
    BayesOptOptions options = config_.bo;
    options.initial_samples = config_.random_samples;
    options.iterations = config_.iterations;
    const UnitObjective objective = [&](const Eigen::VectorXd& u) {
      return Evaluate(space.ToTransform(u));
    };
    const std::vector<Eigen::VectorXd> centre = {Eigen::VectorXd::Constant(space.dimension(), 0.5)};
    return MinimiseBayesOpt(objective, space.Periodic(), options,
                            config_.seed ^ (kStageSalt * static_cast<uint64_t>(stage + 1)), centre);
  }

  const NaiveEvaluation& Best() const {
    return *std::min_element(history_.begin(), history_.end(),
                             [](const NaiveEvaluation& a, const NaiveEvaluation& b) {
                               return a.objective < b.objective;
                             });
  }
  int evaluations() const { return static_cast<int>(history_.size()); }

 private:
  double Evaluate(const Transform& initial) {
    const double gate = config_.EffectiveMaxCorrespondence();
    const reg::RegistrationResult icp = reg::RegistrationICP(
        source_, target_, gate, initial, reg::TransformationEstimationPointToPoint(false),
        reg::ICPConvergenceCriteria(1e-6, 1e-6, config_.icp_max_iterations));
    const double objective =
        TruncatedMean(source_, target_, icp.transformation_, gate, config_.threads);
    history_.push_back({icp.transformation_, objective});
    return objective;
  }

  const PointCloud& source_;
  const PointCloud& target_;
  const BoIcpConfig& config_;
  std::vector<NaiveEvaluation> history_;
};

}  // namespace

MethodOutput RunNaiveBoIcp(const MethodInput& input) {
  const BoIcpConfig config = DatasetBoConfig("C", input);
  const Points search_source = Prepare(input.source, config, config.voxel);
  const PointCloud search_target(Prepare(input.target, config, config.voxel));
  const PointCloud evaluation_source(
      RandomSubsample(search_source, config.evaluation_points, config.seed ^ kSubsampleSalt));

  Transform anchor = Transform::Identity();
  anchor.topRightCorner<3, 1>() = Centroid(search_target.points_) - Centroid(search_source);
  const Point pivot = Centroid(search_source) + anchor.topRightCorner<3, 1>();

  NaiveSearch search(evaluation_source, search_target, config);
  double probability_better = 0.0;
  if (config.mode == SearchMode::kNested) {
    const BayesOptResult rotation = search.RunStage(
        0, MakeSearchSpace(anchor, pivot, config.rotation_bounds, Eigen::Vector3d::Zero()));
    const Transform rotated = search.Best().result;
    const BayesOptResult translation = search.RunStage(
        1, MakeSearchSpace(rotated, pivot, Eigen::Vector3d::Zero(), config.translation_bounds));
    probability_better = std::max(rotation.probability_better, translation.probability_better);
  } else {
    probability_better = search
                             .RunStage(0, MakeSearchSpace(anchor, pivot, config.rotation_bounds,
                                                          config.translation_bounds))
                             .probability_better;
  }

  // RegisterPair's refinement, with Open3D's ICP.
  const PointCloud coarse_source(search_source);
  const reg::RegistrationResult mid =
      reg::RegistrationICP(coarse_source, search_target, 1.5 * config.voxel, search.Best().result,
                           reg::TransformationEstimationPointToPoint(false),
                           reg::ICPConvergenceCriteria(1e-6, 1e-6, config.refine_max_iterations));
  const double fine_voxel = config.EffectiveRefineVoxel();
  const PointCloud fine_source(Prepare(input.source, config, fine_voxel));
  const PointCloud fine_target(Prepare(input.target, config, fine_voxel));
  const reg::RegistrationResult fine =
      reg::RegistrationICP(fine_source, fine_target, 3.0 * fine_voxel, mid.transformation_,
                           reg::TransformationEstimationPointToPoint(false),
                           reg::ICPConvergenceCriteria(1e-6, 1e-6, config.refine_max_iterations));
  const double fitness =
      reg::EvaluateRegistration(fine_source, fine_target, config.EffectiveInlierDistance(),
                                fine.transformation_)
          .fitness_;

  MethodOutput output;
  output.transform = fine.transformation_;
  output.confidence = fitness * (1.0 - probability_better);
  output.evaluations = search.evaluations();
  output.source_points = search_source.size();
  output.target_points = search_target.points_.size();
  output.voxel = config.voxel;
  output.iterations = config.iterations;
  return output;
}

}  // namespace boicp::bench
