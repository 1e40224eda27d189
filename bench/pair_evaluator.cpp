#include "pair_evaluator.hpp"

#include <cmath>

#include "boicp/icp/preprocess.hpp"
#include "evaluation.hpp"

namespace boicp::bench {

PairEvaluator::PairEvaluator(const BenchPair& pair, const DatasetSettings& settings)
    : source_(VoxelDownsample(pair.source, settings.voxel / 3.0)),
      target_(VoxelDownsample(pair.target, settings.voxel / 3.0)),
      expected_(pair.expected),
      error_point_(pair.error_point),
      settings_(settings) {}

PairMetrics PairEvaluator::Evaluate(const Transform& estimate) const {
  PairMetrics m;
  m.rot_err_deg = RotationErrorDeg(estimate, expected_);
  m.trans_err_m = TranslationErrorM(estimate, expected_, error_point_);
  m.success = m.rot_err_deg < settings_.max_rot_deg && m.trans_err_m < settings_.max_trans_m;

  const Eigen::Matrix3d R = estimate.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = estimate.topRightCorner<3, 1>();
  const double gate_sq = settings_.voxel * settings_.voxel;
  size_t inliers = 0, index = 0;
  double sum = 0.0, sq_distance = 0.0;
  for (const Point& p : source_) {
    if (target_.Nearest(R * p + t, gate_sq, index, sq_distance)) {
      ++inliers;
      sum += std::sqrt(sq_distance);
    }
  }
  m.overlap = static_cast<double>(inliers) / static_cast<double>(source_.size());
  m.mean_p2p_m = inliers > 0 ? sum / static_cast<double>(inliers) : NAN;
  return m;
}

}  // namespace boicp::bench
