#include "boicp/icp/icp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "boicp/icp/preprocess.hpp"
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

// A rigid step as one 6-vector: rotation vector times `radius` (metres,
// about how far it moves the cloud's points) and translation.
using Twist = Eigen::Matrix<double, 6, 1>;

Twist TwistOf(const Transform& step, double radius) {
  const Eigen::AngleAxisd rotation(Eigen::Matrix3d(step.topLeftCorner<3, 3>()));
  Twist twist;
  twist.head<3>() = rotation.axis() * rotation.angle() * radius;
  twist.tail<3>() = step.topRightCorner<3, 1>();
  return twist;
}

// The step taken `factor` times over: its rotation angle and its
// translation scaled alike.
Transform ScaledStep(const Transform& step, double factor) {
  const Eigen::AngleAxisd rotation(Eigen::Matrix3d(step.topLeftCorner<3, 3>()));
  Transform scaled = Transform::Identity();
  scaled.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(rotation.angle() * factor, rotation.axis()).toRotationMatrix();
  scaled.topRightCorner<3, 1>() = factor * step.topRightCorner<3, 1>();
  return scaled;
}

// Steps closer than this in direction (cosine) continue one motion.
constexpr double kSameDirection = 0.95;

// How far past `step` a run that took `previous` and then `step` should jump,
// in steps: the rest of the geometric series the two start, or 0 when they
// do not start one.
double ExtrapolationFactor(const Twist& previous, const Twist& step) {
  const double previous_norm = previous.norm(), norm = step.norm();
  if (!(previous_norm > 0.0 && norm > 0.0)) return 0.0;
  if (previous.dot(step) < kSameDirection * previous_norm * norm) return 0.0;
  const double ratio = norm / previous_norm;
  if (ratio >= 1.0) return 0.0;
  return std::min(ratio / (1.0 - ratio), kMaxExtrapolation);
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

namespace {

template <typename SolveStep>
IcpResult RunIcp(const Points& source, const NearestNeighborIndex& target, const Transform& initial,
                 const IcpOptions& options, const std::vector<Transform>& known_ends,
                 const SolveStep& solve_step) {
  IcpResult result;
  result.transform = initial;
  Points moved(source.size());
  std::vector<size_t> match(source.size(), kNoMatch);
  std::vector<double> sq_distance(source.size(), 0.0);
  const double max_sq = options.max_correspondence_distance * options.max_correspondence_distance;
  const bool may_abandon = std::isfinite(options.abandon_above);
  if (may_abandon &&
      !(options.truncation > 0.0 && options.truncation <= options.max_correspondence_distance)) {
    throw InputError("ICP: abandoning needs 0 < truncation <= max_correspondence_distance");
  }
  // Truncated means of the last three iterations, oldest first.
  double history[3] = {0.0, 0.0, 0.0};
  // Extrapolation: the last step's twist, and the pose a jump left from
  // with the fit measured before it.
  const double radius = options.extrapolate ? std::max(RmsRadius(source), 1e-9) : 0.0;
  const double fit_truncation =
      options.truncation > 0.0 ? options.truncation : options.max_correspondence_distance;
  bool may_jump = options.extrapolate;
  Twist previous_step = Twist::Zero();  // zero: none to extrapolate from
  bool jumped = false;
  Transform jumped_from = Transform::Identity();
  double fit = 0.0, fit_before_jump = 0.0;

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

    // Serial reductions in index order keep the sums bit-identical for any thread count.
    size_t count = 0;
    double sum_sq = 0.0;
    for (size_t i = 0; i < source.size(); ++i) {
      if (match[i] == kNoMatch) continue;
      ++count;
      sum_sq += sq_distance[i];
    }
    result.iterations = iteration + 1;
    result.correspondences = count;
    if (count < 3) {
      result.rmse = 0.0;
      result.converged = false;
      return result;
    }
    result.rmse = std::sqrt(sum_sq / static_cast<double>(count));
    if (options.extrapolate) {
      fit = TruncatedMean(match, sq_distance, fit_truncation);
      if (jumped && fit > fit_before_jump) {
        result.transform = jumped_from;  // match again where the jump started
        jumped = false;
        may_jump = false;
        continue;
      }
      jumped = false;
    }
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
    const Transform step = solve_step(moved, match);
    result.transform = step * result.transform;
    if (TranslationNorm(step) < options.convergence_translation &&
        RotationAngle(step) < options.convergence_rotation) {
      result.converged = true;
      break;
    }
    if (may_jump) {
      const Twist twist = TwistOf(step, radius);
      const double factor = ExtrapolationFactor(previous_step, twist);
      if (factor > 0.0) {
        jumped = true;
        jumped_from = result.transform;
        fit_before_jump = fit;
        result.transform = ScaledStep(step, factor) * result.transform;
        previous_step = Twist::Zero();
      } else {
        previous_step = twist;
      }
    }
  }
  return result;
}

// The rigid motion that best maps the matched moved points onto their target
// points (Kabsch). Precondition: at least 3 matches.
Transform PointToPointStep(const Points& moved, const std::vector<size_t>& match,
                           const Points& target_points) {
  size_t count = 0;
  Point source_mean = Point::Zero(), target_mean = Point::Zero();
  for (size_t i = 0; i < moved.size(); ++i) {
    if (match[i] == kNoMatch) continue;
    ++count;
    source_mean += moved[i];
    target_mean += target_points[match[i]];
  }
  source_mean /= static_cast<double>(count);
  target_mean /= static_cast<double>(count);
  Eigen::Matrix3d cross_covariance = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < moved.size(); ++i) {
    if (match[i] == kNoMatch) continue;
    cross_covariance +=
        (moved[i] - source_mean) * (target_points[match[i]] - target_mean).transpose();
  }
  return RigidFromCrossCovariance(source_mean, target_mean, cross_covariance);
}

// One Gauss-Newton step on the sum of squared distances from the moved points
// to their matches' tangent planes, linearised in a small rotation w and a
// translation t: r_i + (p_i x n_i) . w + n_i . t. Matches without a normal do
// not count; with fewer than 6 that have one, the point-to-point step is used.
Transform PointToPlaneStep(const Points& moved, const std::vector<size_t>& match,
                           const Points& target_points, const Points& target_normals) {
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
  Vector6d Jtr = Vector6d::Zero();
  size_t used = 0;
  for (size_t i = 0; i < moved.size(); ++i) {
    if (match[i] == kNoMatch) continue;
    const Point& n = target_normals[match[i]];
    if (n.isZero()) continue;
    Vector6d J;
    J << moved[i].cross(n), n;
    JtJ.selfadjointView<Eigen::Upper>().rankUpdate(J);
    Jtr += J * (moved[i] - target_points[match[i]]).dot(n);
    ++used;
  }
  if (used < 6) return PointToPointStep(moved, match, target_points);
  // A direction no plane constrains (along a corridor) gets a near-zero step
  // instead of an arbitrary one.
  JtJ.diagonal().array() += 1e-6 * JtJ.trace() / 6.0;
  const Vector6d x = JtJ.selfadjointView<Eigen::Upper>().ldlt().solve(-Jtr);
  if (!x.allFinite()) return PointToPointStep(moved, match, target_points);
  Transform step = Transform::Identity();
  const Eigen::Vector3d w = x.head<3>();
  if (w.norm() > 0.0) {
    step.topLeftCorner<3, 3>() = Eigen::AngleAxisd(w.norm(), w / w.norm()).toRotationMatrix();
  }
  step.topRightCorner<3, 1>() = x.tail<3>();
  return step;
}

}  // namespace

IcpResult AlignPointToPoint(const Points& source, const NearestNeighborIndex& target,
                            const Transform& initial, const IcpOptions& options,
                            const std::vector<Transform>& known_ends) {
  const Points& target_points = target.points();
  return RunIcp(source, target, initial, options, known_ends,
                [&](const Points& moved, const std::vector<size_t>& match) {
                  return PointToPointStep(moved, match, target_points);
                });
}

IcpResult AlignPointToPlane(const Points& source, const NearestNeighborIndex& target,
                            const Points& target_normals, const Transform& initial,
                            const IcpOptions& options, const std::vector<Transform>& known_ends) {
  if (target_normals.size() != target.size()) {
    throw InputError("point-to-plane ICP: " + std::to_string(target_normals.size()) +
                     " normals for " + std::to_string(target.size()) + " target points");
  }
  const Points& target_points = target.points();
  return RunIcp(source, target, initial, options, known_ends,
                [&](const Points& moved, const std::vector<size_t>& match) {
                  return PointToPlaneStep(moved, match, target_points, target_normals);
                });
}

}  // namespace boicp
