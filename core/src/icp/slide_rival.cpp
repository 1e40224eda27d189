#include "boicp/icp/slide_rival.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "boicp/icp/alignment_score.hpp"
#include "boicp/util/percentile.hpp"

namespace boicp {
namespace {

// More offsets than this either way cost more than the rest of the answer's
// scoring; beyond it the slide steps by more than an inlier distance.
constexpr int kMaxOffsetsEachWay = 32;

// The 90th percentile of the moved source's distance from its mean along
// `axis`: how far it can slide before it leaves its own footprint.
double ExtentAlong(const Points& source, const Transform& T, const Eigen::Vector3d& axis) {
  std::vector<double> along;
  along.reserve(source.size());
  double mean = 0.0;
  for (const Point& p : source) {
    along.push_back(axis.dot(T.topLeftCorner<3, 3>() * p + T.topRightCorner<3, 1>()));
    mean += along.back();
  }
  mean /= static_cast<double>(along.size());
  for (double& a : along) a = std::abs(a - mean);
  return Percentile(std::move(along), 0.9);
}

}  // namespace

double SlideRivalShare(const Points& source, const NearestNeighborIndex& target,
                       const Transform& T_target_source, const Eigen::Vector3d& axis,
                       double inlier_distance) {
  const double own = ScoreAlignment(source, target, T_target_source, inlier_distance).fitness;
  if (!(own > 0.0)) return 0.0;
  const double extent = ExtentAlong(source, T_target_source, axis);
  const double start = std::max(kRivalSlideStart * inlier_distance, kRivalSlideShare * extent);
  if (extent < start) return 0.0;
  const double step = std::max(inlier_distance, (extent - start) / kMaxOffsetsEachWay);
  double best = 0.0;
  for (double offset = start; offset <= extent; offset += step) {
    for (const double signed_offset : {offset, -offset}) {
      Transform slid = T_target_source;
      slid.topRightCorner<3, 1>() += signed_offset * axis;
      const double f = ScoreAlignment(source, target, slid, inlier_distance).fitness;
      best = std::max(best, f);
    }
  }
  return best / own;
}

}  // namespace boicp
