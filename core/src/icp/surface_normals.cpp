#include "boicp/icp/surface_normals.hpp"

#include <vector>

#include <Eigen/Eigenvalues>

#include "boicp/util/parallel_for.hpp"

namespace boicp {
namespace {

constexpr size_t kNeighbours = 10;
constexpr size_t kFewestNeighbours = 5;

// The eigenvector of the smallest eigenvalue of the neighbours' covariance,
// or zero when the two larger eigenvalues do not span a plane.
Point PlaneNormal(const Points& points, const std::vector<size_t>& neighbours) {
  Point mean = Point::Zero();
  for (const size_t i : neighbours) mean += points[i];
  mean /= static_cast<double>(neighbours.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const size_t i : neighbours) {
    const Point d = points[i] - mean;
    covariance += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3d spread = solver.eigenvalues();  // ascending
  // Collinear neighbours (a pole, a scan line) leave the plane undetermined.
  if (!(spread(1) > 1e-3 * spread(2))) return Point::Zero();
  return solver.eigenvectors().col(0).normalized();
}

}  // namespace

Point SurfaceNormalAt(const NearestNeighborIndex& cloud, const Point& at, double radius) {
  std::vector<size_t> neighbours;
  cloud.KNearest(at, kNeighbours, radius * radius, neighbours);
  if (neighbours.size() < kFewestNeighbours) return Point::Zero();
  return PlaneNormal(cloud.points(), neighbours);
}

Points EstimateSurfaceNormals(const NearestNeighborIndex& cloud, double radius, int threads) {
  const Points& points = cloud.points();
  Points normals(points.size(), Point::Zero());
  ParallelForRanges(points.size(), threads, [&](size_t begin, size_t end) {
    std::vector<size_t> neighbours;
    for (size_t i = begin; i < end; ++i) {
      cloud.KNearest(points[i], kNeighbours, radius * radius, neighbours);
      if (neighbours.size() >= kFewestNeighbours) normals[i] = PlaneNormal(points, neighbours);
    }
  });
  return normals;
}

}  // namespace boicp
