#include "boicp/mapping/place_recognition.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "boicp/util/percentile.hpp"

namespace boicp {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Heights are measured from this quantile of the scan's points, so that a
// stray point below the road does not lift every bin.
constexpr double kFloorQuantile = 0.01;

// An occupied bin's least height: a bin holding only the floor still counts
// as holding points.
constexpr float kOccupiedHeight = 1e-3F;

// Where a point falls on the grid: its ring and sector, or none beyond the radius.
struct GridCell {
  int ring = -1;
  int sector = -1;
};

GridCell CellOf(const Point& offset, const PlaceGrid& grid) {
  const double radius = std::hypot(offset.x(), offset.y());
  if (!(radius < grid.max_radius)) return {};
  const double azimuth = std::atan2(offset.y(), offset.x()) + kPi;  // [0, 2 pi]
  GridCell cell;
  cell.ring = std::min(grid.rings - 1, static_cast<int>(radius / grid.max_radius * grid.rings));
  cell.sector = std::min(grid.sectors - 1, static_cast<int>(azimuth / (2 * kPi) * grid.sectors));
  return cell;
}

double FloorHeight(PointSpan points, const Point& sensor_origin, const PlaceGrid& grid) {
  std::vector<double> heights;
  heights.reserve(points.size());
  for (const Point& p : points) {
    if (CellOf(p - sensor_origin, grid).ring >= 0) heights.push_back(p.z() - sensor_origin.z());
  }
  return heights.empty() ? 0.0 : Percentile(std::move(heights), kFloorQuantile);
}

}  // namespace

PlaceDescriptor DescribePlace(PointSpan points, const Point& sensor_origin, const PlaceGrid& grid) {
  const double floor = FloorHeight(points, sensor_origin, grid);
  Eigen::MatrixXf heights = Eigen::MatrixXf::Zero(grid.rings, grid.sectors);
  for (const Point& p : points) {
    const Point offset = p - sensor_origin;
    const GridCell cell = CellOf(offset, grid);
    if (cell.ring < 0) continue;
    const auto height = std::max(kOccupiedHeight, static_cast<float>(offset.z() - floor));
    heights(cell.ring, cell.sector) = std::max(heights(cell.ring, cell.sector), height);
  }
  const Eigen::Array<bool, 1, Eigen::Dynamic> filled = (heights.array() > 0.0F).colwise().any();
  if (filled.count() < kPlaceMinSectorShare * grid.sectors) return {};
  PlaceDescriptor descriptor;
  descriptor.ring_key =
      (heights.array() > 0.0F).cast<float>().rowwise().sum() / static_cast<float>(grid.sectors);
  descriptor.heights = std::move(heights);
  return descriptor;
}

double PlaceRadius(PointSpan points, const Point& sensor_origin) {
  if (points.empty()) return 0.0;
  std::vector<double> radii;
  radii.reserve(points.size());
  for (const Point& p : points) {
    radii.push_back(std::hypot(p.x() - sensor_origin.x(), p.y() - sensor_origin.y()));
  }
  return Percentile(std::move(radii), 0.95);
}

PlaceMatch MatchPlaces(const PlaceDescriptor& source, const PlaceDescriptor& target) {
  const Eigen::Index sectors = source.heights.cols();
  const Eigen::RowVectorXf source_norms = source.heights.colwise().norm();
  const Eigen::RowVectorXf target_norms = target.heights.colwise().norm();
  PlaceMatch best;
  Eigen::Index best_shift = 0;
  for (Eigen::Index shift = 0; shift < sectors; ++shift) {
    double cosines = 0.0;
    int common = 0;
    for (Eigen::Index c = 0; c < sectors; ++c) {
      const Eigen::Index t = (c + shift) % sectors;
      if (source_norms(c) <= 0.0F || target_norms(t) <= 0.0F) continue;
      cosines +=
          source.heights.col(c).dot(target.heights.col(t)) / (source_norms(c) * target_norms(t));
      ++common;
    }
    if (common == 0) continue;
    const double distance = 1.0 - cosines / common;
    if (distance < best.distance) {
      best.distance = distance;
      best_shift = shift;
    }
  }
  // Source sector c lies on target sector c + shift: the source turned by
  // shift sectors.
  const double yaw = 2 * kPi * static_cast<double>(best_shift) / static_cast<double>(sectors);
  best.yaw = yaw > kPi ? yaw - 2 * kPi : yaw;
  return best;
}

Transform PlacePrior(const PlaceMatch& match, const Point& source_origin,
                     const Point& target_origin) {
  Transform prior = Transform::Identity();
  prior.topLeftCorner<3, 3>() = Eigen::AngleAxisd(match.yaw, Point::UnitZ()).toRotationMatrix();
  prior.topRightCorner<3, 1>() = target_origin - prior.topLeftCorner<3, 3>() * source_origin;
  return prior;
}

}  // namespace boicp
