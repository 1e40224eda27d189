#include "boicp/registration/fpfh_features.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "boicp/util/parallel_for.hpp"

namespace boicp {
namespace {

constexpr int kFpfhBinsPerFeature = 11;
constexpr int kFpfhDescriptorSize = 3 * kFpfhBinsPerFeature;
constexpr double kFpfhBlockTotal = 100.0;

using SpfhMatrix = Eigen::Matrix<double, kFpfhDescriptorSize, Eigen::Dynamic>;
using FpfhColumn = Eigen::Matrix<double, kFpfhDescriptorSize, 1>;

// A neighbour that can take part in a pair feature: another point, not at the
// same place, with a normal.
struct FpfhNeighbour {
  size_t index = 0;
  double squared_distance = 0.0;
};

// Rusu's pair feature of two oriented points in the Darboux frame (u, v, w)
// at the first: the angle of the second normal in the u-w plane, its cosine
// with v, and the cosine of u with the line to the second point.
struct PairFeature {
  double angle = 0.0;   // f1, radians in [-pi, pi]
  double cos_v = 0.0;   // f2 in [-1, 1]
  double cos_uv = 0.0;  // f3 in [-1, 1]
};

// The normal's sign is arbitrary, and flipping one changes every feature it
// enters; facing the sensor fixes it in a way rotations about the sensor
// preserve.
Point FacingViewpoint(const Point& point, const Point& normal, const Point& viewpoint) {
  return normal.dot(point - viewpoint) > 0.0 ? Point(-normal) : normal;
}

// Precondition: p_s != p_t. The frame sits at whichever point's normal is
// closer to the connecting line, so that the feature does not depend on the
// order of the pair. A normal along the line leaves v undefined: the zero
// feature stands for it, as in Open3D.
PairFeature ComputePairFeature(const Point& p_s, const Point& n_s, const Point& p_t,
                               const Point& n_t) {
  Point line = p_t - p_s;
  const double distance = line.norm();
  const double cos_s = n_s.dot(line) / distance;
  const double cos_t = n_t.dot(line) / distance;
  PairFeature feature;
  Point u = n_s;
  Point other = n_t;
  feature.cos_uv = cos_s;
  if (std::abs(cos_s) < std::abs(cos_t)) {
    u = n_t;
    other = n_s;
    line = -line;
    feature.cos_uv = -cos_t;
  }
  Point v = line.cross(u);
  const double v_norm = v.norm();
  if (v_norm == 0.0) return PairFeature{};
  v /= v_norm;
  const Point w = u.cross(v);
  feature.cos_v = v.dot(other);
  feature.angle = std::atan2(w.dot(other), u.dot(other));
  return feature;
}

// Bin of `value` when [low, high] is cut into kFpfhBinsPerFeature equal bins.
int FeatureBin(double value, double low, double high) {
  const auto bin = static_cast<int>(std::floor(kFpfhBinsPerFeature * (value - low) / (high - low)));
  return std::clamp(bin, 0, kFpfhBinsPerFeature - 1);
}

// Neighbours of point i within the radius that can pair with it, nearest first.
std::vector<FpfhNeighbour> PairableNeighbours(const NearestNeighborIndex& cloud,
                                              const Points& normals, size_t i,
                                              double squared_radius, size_t max_neighbours,
                                              std::vector<size_t>& scratch) {
  const Points& points = cloud.points();
  // One more than asked, as the search returns the point itself.
  cloud.KNearest(points[i], std::min(max_neighbours, points.size()) + 1, squared_radius, scratch);
  std::vector<FpfhNeighbour> neighbours;
  neighbours.reserve(scratch.size());
  for (const size_t j : scratch) {
    if (j == i || normals[j].isZero()) continue;
    const double squared_distance = (points[j] - points[i]).squaredNorm();
    if (squared_distance == 0.0) continue;
    if (neighbours.size() == max_neighbours) break;
    neighbours.push_back({j, squared_distance});
  }
  return neighbours;
}

// The simplified point feature histogram of point i: its pair features with
// each neighbour, binned 11 per feature, each block summing to 100. Zero when
// the point has no normal or no neighbour.
FpfhColumn SimplifiedHistogram(const Points& points, const Points& oriented_normals, size_t i,
                               const std::vector<FpfhNeighbour>& neighbours) {
  FpfhColumn histogram = FpfhColumn::Zero();
  if (neighbours.empty() || oriented_normals[i].isZero()) return histogram;
  const double increment = kFpfhBlockTotal / static_cast<double>(neighbours.size());
  for (const FpfhNeighbour& neighbour : neighbours) {
    const PairFeature f = ComputePairFeature(
        points[i], oriented_normals[i], points[neighbour.index], oriented_normals[neighbour.index]);
    histogram(FeatureBin(f.angle, -M_PI, M_PI)) += increment;
    histogram(kFpfhBinsPerFeature + FeatureBin(f.cos_v, -1.0, 1.0)) += increment;
    histogram(2 * kFpfhBinsPerFeature + FeatureBin(f.cos_uv, -1.0, 1.0)) += increment;
  }
  return histogram;
}

// Scales each 11-bin block to sum to 100; an empty block stays zero.
void NormaliseBlocks(FpfhColumn& histogram) {
  for (int block = 0; block < 3; ++block) {
    auto bins = histogram.segment<kFpfhBinsPerFeature>(block * kFpfhBinsPerFeature);
    const double sum = bins.sum();
    if (sum > 0.0) bins *= kFpfhBlockTotal / sum;
  }
}

// FPFH(i) = SPFH(i) + the neighbours' SPFH weighted by 1 / squared distance,
// the neighbours' share scaled to the weight of the point's own (as Open3D
// does), then normalised per block.
FpfhColumn FastHistogram(const SpfhMatrix& spfh, size_t i,
                         const std::vector<FpfhNeighbour>& neighbours) {
  FpfhColumn from_neighbours = FpfhColumn::Zero();
  for (const FpfhNeighbour& neighbour : neighbours) {
    from_neighbours +=
        spfh.col(static_cast<Eigen::Index>(neighbour.index)) / neighbour.squared_distance;
  }
  NormaliseBlocks(from_neighbours);
  FpfhColumn histogram = spfh.col(static_cast<Eigen::Index>(i)) + from_neighbours;
  NormaliseBlocks(histogram);
  return histogram;
}

void CheckFpfhInputs(const NearestNeighborIndex& cloud, const Points& normals, double radius,
                     size_t max_neighbours) {
  if (normals.size() != cloud.size()) {
    throw InputError("FPFH: " + std::to_string(normals.size()) + " normals for " +
                     std::to_string(cloud.size()) + " points");
  }
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    throw InputError("FPFH: radius must be a positive number of metres, got " +
                     std::to_string(radius));
  }
  if (max_neighbours < 1) throw InputError("FPFH: max_neighbours must be at least 1");
}

}  // namespace

FpfhFeatures ComputeFpfhFeatures(const NearestNeighborIndex& cloud, const Points& normals,
                                 double radius, int threads, size_t max_neighbours,
                                 const Point& viewpoint) {
  CheckFpfhInputs(cloud, normals, radius, max_neighbours);
  const Points& points = cloud.points();
  const size_t n = points.size();
  Points oriented(n);
  for (size_t i = 0; i < n; ++i) oriented[i] = FacingViewpoint(points[i], normals[i], viewpoint);

  std::vector<std::vector<FpfhNeighbour>> neighbourhoods(n);
  SpfhMatrix spfh(kFpfhDescriptorSize, static_cast<Eigen::Index>(n));
  ParallelForRanges(n, threads, [&](size_t begin, size_t end) {
    std::vector<size_t> scratch;
    for (size_t i = begin; i < end; ++i) {
      neighbourhoods[i] =
          PairableNeighbours(cloud, normals, i, radius * radius, max_neighbours, scratch);
      spfh.col(static_cast<Eigen::Index>(i)) =
          SimplifiedHistogram(points, oriented, i, neighbourhoods[i]);
    }
  });

  FpfhFeatures features(kFpfhDescriptorSize, static_cast<Eigen::Index>(n));
  ParallelForRanges(n, threads, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      features.col(static_cast<Eigen::Index>(i)) =
          FastHistogram(spfh, i, neighbourhoods[i]).cast<float>();
    }
  });
  return features;
}

}  // namespace boicp
