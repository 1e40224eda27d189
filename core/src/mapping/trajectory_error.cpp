#include "boicp/mapping/trajectory_error.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>

namespace boicp {
namespace {

Point Position(const Transform& T) { return T.topRightCorner<3, 1>(); }

// Metres along the reference path from its first known pose to each scan
// (NaN where the scan has no reference).
std::vector<double> PathLengths(const std::vector<std::optional<Transform>>& reference) {
  std::vector<double> along(reference.size(), std::numeric_limits<double>::quiet_NaN());
  std::optional<Point> previous;
  double travelled = 0.0;
  for (size_t i = 0; i < reference.size(); ++i) {
    if (!reference[i]) continue;
    if (previous) travelled += (Position(*reference[i]) - *previous).norm();
    previous = Position(*reference[i]);
    along[i] = travelled;
  }
  return along;
}

}  // namespace

TrajectoryError CompareTrajectories(const std::vector<Transform>& poses,
                                    const std::vector<std::optional<Transform>>& reference,
                                    double segment) {
  if (poses.size() != reference.size()) {
    throw InputError("trajectory error: " + std::to_string(poses.size()) + " poses for " +
                     std::to_string(reference.size()) + " reference poses");
  }
  std::vector<size_t> known;
  for (size_t i = 0; i < reference.size(); ++i) {
    if (reference[i]) known.push_back(i);
  }
  // Two positions align rigidly up to a turn about the line through them,
  // which moves neither.
  if (known.size() < 2) throw InputError("trajectory error: fewer than 2 scans have a reference");

  TrajectoryError error;
  error.scans = static_cast<int>(known.size());
  Eigen::Matrix3Xd from(3, known.size()), to(3, known.size());
  for (size_t k = 0; k < known.size(); ++k) {
    from.col(static_cast<Eigen::Index>(k)) = Position(poses[known[k]]);
    to.col(static_cast<Eigen::Index>(k)) = Position(*reference[known[k]]);
  }
  const Eigen::Matrix4d align = Eigen::umeyama(from, to, /*with_scaling=*/false);
  error.per_scan.assign(poses.size(), std::numeric_limits<double>::quiet_NaN());
  double squared = 0.0;
  for (const size_t i : known) {
    const Point aligned =
        align.topLeftCorner<3, 3>() * Position(poses[i]) + align.topRightCorner<3, 1>();
    error.per_scan[i] = (aligned - Position(*reference[i])).norm();
    squared += error.per_scan[i] * error.per_scan[i];
    error.ate_max = std::max(error.ate_max, error.per_scan[i]);
  }
  error.ate_rmse = std::sqrt(squared / static_cast<double>(known.size()));

  const std::vector<double> along = PathLengths(reference);
  error.segment = segment > 0.0 ? segment : along[known.back()] / 10.0;
  if (!(error.segment > 0.0)) return error;
  double drift = 0.0;
  size_t end = 0;
  for (size_t a = 0; a < known.size(); ++a) {
    const size_t i = known[a];
    end = std::max(end, a + 1);
    while (end < known.size() && along[known[end]] - along[i] < error.segment) ++end;
    if (end == known.size()) break;
    const size_t j = known[end];
    const Transform estimated = poses[i].inverse() * poses[j];
    const Transform truth = reference[i]->inverse() * *reference[j];
    drift += Position(Transform(truth.inverse() * estimated)).norm() / (along[j] - along[i]);
    ++error.segments;
  }
  if (error.segments > 0) error.drift_per_metre = drift / error.segments;
  return error;
}

}  // namespace boicp
