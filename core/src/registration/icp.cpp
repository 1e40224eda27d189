#include "boicp/registration/icp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/SVD>

#include "boicp/util/parallel_for.hpp"

namespace boicp {
namespace {

constexpr size_t kNoMatch = std::numeric_limits<size_t>::max();

// Matches every source point (moved by R, t) to its nearest target point within
// the gate. Each point writes only its own slot, so the parallel loop gives the
// same result as the serial one.
void MatchNearest(const Points& source, const NearestNeighborIndex& target,
                  const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double max_sq_distance,
                  int threads, Points& moved, std::vector<size_t>& match,
                  std::vector<double>& sq_distance) {
  ParallelForRanges(source.size(), threads, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      moved[i] = R * source[i] + t;
      size_t index = 0;
      double d2 = 0.0;
      // The previous iteration's match is close after a small step and bounds the search.
      const bool found = match[i] == kNoMatch ? target.Nearest(moved[i], max_sq_distance, index, d2)
                                              : target.NearestWithHint(moved[i], match[i],
                                                                       max_sq_distance, index, d2);
      if (found) {
        match[i] = index;
        sq_distance[i] = d2;
      } else {
        match[i] = kNoMatch;
      }
    }
  });
}

// Mean of every point's distance clipped at tau; unmatched points (beyond the
// gate, which is at least tau) count as tau.
double TruncatedMean(const std::vector<size_t>& match, const std::vector<double>& sq_distance,
                     double tau) {
  double sum = 0.0;
  for (size_t i = 0; i < match.size(); ++i) {
    sum += match[i] == kNoMatch ? tau : std::min(std::sqrt(sq_distance[i]), tau);
  }
  return sum / static_cast<double>(std::max<size_t>(match.size(), 1));
}

// Index of the known end nearest to T in translation among those within both
// join radii, or -1.
int JoinedEnd(const Transform& T, const std::vector<Transform>& known_ends,
              const IcpOptions& options) {
  if (!(options.join_translation > 0.0)) return -1;
  int joined = -1;
  double nearest = options.join_translation;
  for (size_t k = 0; k < known_ends.size(); ++k) {
    const Transform delta = known_ends[k].inverse() * T;
    const double distance = TranslationNorm(delta);
    if (distance <= nearest && RotationAngle(delta) <= options.join_rotation) {
      nearest = distance;
      joined = static_cast<int>(k);
    }
  }
  return joined;
}

}  // namespace

double ProjectedLimit(double f0, double f1, double f2, int remaining_steps) {
  const double fastest = std::max({f0 - f1, f1 - f2, 0.0});
  return f2 - fastest * static_cast<double>(std::max(remaining_steps, 0));
}

Transform RigidFromCrossCovariance(const Point& source_mean, const Point& target_mean,
                                   const Eigen::Matrix3d& cross_covariance) {
  // H = sum (p - p_mean)(q - q_mean)^T = U S V^T; R = V diag(1, 1, det(V U^T)) U^T.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross_covariance,
                                        Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d reflection_fix = Eigen::Matrix3d::Identity();
  reflection_fix(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d R = svd.matrixV() * reflection_fix * svd.matrixU().transpose();
  Transform T = Transform::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = target_mean - R * source_mean;
  return T;
}

IcpResult AlignPointToPoint(const Points& source, const NearestNeighborIndex& target,
                            const Transform& initial, const IcpOptions& options,
                            const std::vector<Transform>& known_ends) {
  IcpResult result;
  result.transform = initial;
  Points moved(source.size());
  std::vector<size_t> match(source.size(), kNoMatch);
  std::vector<double> sq_distance(source.size(), 0.0);
  const double max_sq = options.max_correspondence_distance * options.max_correspondence_distance;
  const Points& target_points = target.points();
  const bool may_abandon = std::isfinite(options.abandon_above);
  if (may_abandon &&
      !(options.truncation > 0.0 && options.truncation <= options.max_correspondence_distance)) {
    throw InputError("ICP: abandoning needs 0 < truncation <= max_correspondence_distance");
  }
  // Truncated means of the last three iterations, oldest first.
  double history[3] = {0.0, 0.0, 0.0};

  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    result.joined_end = JoinedEnd(result.transform, known_ends, options);
    if (result.joined_end >= 0) {
      result.transform = known_ends[result.joined_end];
      result.converged = true;
      return result;
    }
    const Eigen::Matrix3d R = result.transform.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = result.transform.topRightCorner<3, 1>();
    MatchNearest(source, target, R, t, max_sq, options.threads, moved, match, sq_distance);

    // Serial reduction in index order keeps the sums bit-identical for any thread count.
    size_t count = 0;
    double sum_sq = 0.0;
    Point source_mean = Point::Zero(), target_mean = Point::Zero();
    for (size_t i = 0; i < source.size(); ++i) {
      if (match[i] == kNoMatch) continue;
      ++count;
      sum_sq += sq_distance[i];
      source_mean += moved[i];
      target_mean += target_points[match[i]];
    }
    result.iterations = iteration + 1;
    result.correspondences = count;
    if (count < 3) {
      result.rmse = 0.0;
      result.converged = false;
      return result;
    }
    result.rmse = std::sqrt(sum_sq / static_cast<double>(count));
    if (may_abandon) {
      history[0] = history[1];
      history[1] = history[2];
      history[2] = TruncatedMean(match, sq_distance, options.truncation);
      if (iteration + 1 >= std::max(options.abandon_after, 3) &&
          ProjectedLimit(history[0], history[1], history[2],
                         options.max_iterations - iteration - 1) > options.abandon_above) {
        result.abandoned = true;
        return result;
      }
    }
    source_mean /= static_cast<double>(count);
    target_mean /= static_cast<double>(count);
    Eigen::Matrix3d cross_covariance = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < source.size(); ++i) {
      if (match[i] == kNoMatch) continue;
      cross_covariance +=
          (moved[i] - source_mean) * (target_points[match[i]] - target_mean).transpose();
    }
    const Transform step = RigidFromCrossCovariance(source_mean, target_mean, cross_covariance);
    result.transform = step * result.transform;
    if (TranslationNorm(step) < options.convergence_translation &&
        RotationAngle(step) < options.convergence_rotation) {
      result.converged = true;
      break;
    }
  }
  return result;
}

}  // namespace boicp
