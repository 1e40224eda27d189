#include "boicp/icp/alignment_score.hpp"

#include <algorithm>
#include <cmath>

#include "boicp/util/parallel_for.hpp"

namespace boicp {

AlignmentScore ScoreAlignment(const Points& source, const NearestNeighborIndex& target,
                              const Transform& T, double tau, int threads) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  const double tau_sq = tau * tau;
  std::vector<double> sq_distance(source.size());
  ParallelForRanges(source.size(), threads, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      size_t index = 0;
      double d2 = 0.0;
      sq_distance[i] = target.Nearest(R * source[i] + t, tau_sq, index, d2) ? d2 : tau_sq;
    }
  });

  // Serial sums in index order: identical for every thread count.
  AlignmentScore score;
  size_t inliers = 0;
  double clipped_sum = 0.0, inlier_sq_sum = 0.0;
  for (double d2 : sq_distance) {
    if (d2 < tau_sq) {
      ++inliers;
      inlier_sq_sum += d2;
      clipped_sum += std::sqrt(d2);
    } else {
      clipped_sum += tau;
    }
  }
  const double count = static_cast<double>(std::max<size_t>(source.size(), 1));
  score.truncated_mean = clipped_sum / count;
  score.fitness = static_cast<double>(inliers) / count;
  score.inlier_rmse = inliers > 0 ? std::sqrt(inlier_sq_sum / static_cast<double>(inliers)) : 0.0;
  return score;
}

}  // namespace boicp
