#include "boicp/registration/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <open3d/geometry/PointCloud.h>

namespace boicp {

Points CropByRange(const Points& points, double min_range, double max_range) {
  const double min_sq = min_range * min_range;
  const double max_sq = max_range > 0.0 ? max_range * max_range : -1.0;
  Points kept;
  kept.reserve(points.size());
  for (const Point& p : points) {
    const double r_sq = p.squaredNorm();
    if (r_sq < min_sq) continue;
    if (max_sq >= 0.0 && r_sq > max_sq) continue;
    kept.push_back(p);
  }
  return kept;
}

Points VoxelDownsample(const Points& points, double voxel) {
  if (voxel <= 0.0 || points.empty()) return points;
  open3d::geometry::PointCloud cloud(points);
  return cloud.VoxelDownSample(voxel)->points_;
}

Points RandomSubsample(const Points& points, size_t max_points, uint64_t seed) {
  if (max_points == 0 || max_points >= points.size()) return points;
  std::vector<size_t> indices(points.size());
  std::iota(indices.begin(), indices.end(), size_t{0});
  std::mt19937_64 rng(seed);
  // Partial Fisher-Yates: the first max_points entries become a uniform sample.
  for (size_t i = 0; i < max_points; ++i) {
    std::uniform_int_distribution<size_t> pick(i, indices.size() - 1);
    std::swap(indices[i], indices[pick(rng)]);
  }
  indices.resize(max_points);
  std::sort(indices.begin(), indices.end());
  Points sample;
  sample.reserve(max_points);
  for (size_t i : indices) sample.push_back(points[i]);
  return sample;
}

Point Centroid(const Points& points) {
  Point sum = Point::Zero();
  for (const Point& p : points) sum += p;
  return points.empty() ? sum : Point(sum / static_cast<double>(points.size()));
}

double RmsRadius(const Points& points) {
  if (points.empty()) return 0.0;
  const Point centre = Centroid(points);
  Eigen::Vector3d squares = Eigen::Vector3d::Zero();
  for (const Point& p : points) squares += (p - centre).cwiseAbs2();
  squares /= static_cast<double>(points.size());
  return std::sqrt(squares.sum());
}

}  // namespace boicp
