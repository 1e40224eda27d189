#include "boicp/icp/free_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace boicp {
namespace {

// Directions are binned on a cube about the sensor, kFaceCells by
// kFaceCells on each face: cells of 0.9 degrees at a face's centre and no
// pole where cells shrink to nothing (a depth camera looks along one axis).
constexpr int kFaceCells = 128;

// The cell of direction `d`, or -1 for d = 0.
int CellOf(const Point& d) {
  Eigen::Index axis = 0;
  const double major = d.cwiseAbs().maxCoeff(&axis);
  if (major == 0.0) return -1;
  const int face = 2 * static_cast<int>(axis) + (d[axis] < 0.0 ? 1 : 0);
  const auto cell = [&](Eigen::Index other) {
    const double u = 0.5 * (d[other] / major + 1.0);  // [0, 1]
    return std::min(kFaceCells - 1, static_cast<int>(u * kFaceCells));
  };
  return (face * kFaceCells + cell((axis + 1) % 3)) * kFaceCells + cell((axis + 2) % 3);
}

}  // namespace

RangeImage::RangeImage(const Points& points, const Point& sensor)
    : sensor_(sensor),
      nearest_(6 * kFaceCells * kFaceCells, std::numeric_limits<float>::infinity()) {
  for (const Point& p : points) {
    const int cell = CellOf(p - sensor_);
    if (cell < 0) continue;
    float& nearest = nearest_[static_cast<size_t>(cell)];
    if (std::isinf(nearest)) ++covered_;
    nearest = std::min(nearest, static_cast<float>((p - sensor_).norm()));
  }
}

double RangeImage::NearestReturn(const Point& p) const {
  const int cell = CellOf(p - sensor_);
  return cell < 0 ? std::numeric_limits<double>::infinity() : nearest_[static_cast<size_t>(cell)];
}

double SeenThroughShare(const Points& source, const NearestNeighborIndex& target,
                        const RangeImage& view, const Transform& T, double margin,
                        double inlier_distance) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  const double inlier_sq = inlier_distance * inlier_distance;
  size_t seen = 0, through = 0;
  for (const Point& s : source) {
    const Point p = R * s + t;
    const double nearest = view.NearestReturn(p);
    if (std::isinf(nearest)) continue;
    ++seen;
    const double range = (p - view.sensor()).norm();
    if (range >= nearest - std::max(margin, 0.05 * nearest)) continue;
    size_t index = 0;
    double d2 = 0.0;
    if (!target.Nearest(p, inlier_sq, index, d2)) ++through;
  }
  return seen > 0 ? static_cast<double>(through) / static_cast<double>(seen) : 0.0;
}

}  // namespace boicp
