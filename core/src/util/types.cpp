#include "boicp/util/types.hpp"

#include <algorithm>
#include <cmath>

namespace boicp {

Points TransformPoints(const Transform& T, const Points& points) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  Points out;
  out.reserve(points.size());
  for (const Point& p : points) out.emplace_back(R * p + t);
  return out;
}

double RotationAngle(const Transform& T) {
  // acos((trace - 1) / 2), clamped against rounding just outside [-1, 1].
  const double c = (T.topLeftCorner<3, 3>().trace() - 1.0) / 2.0;
  return std::acos(std::clamp(c, -1.0, 1.0));
}

double TranslationNorm(const Transform& T) { return T.topRightCorner<3, 1>().norm(); }

}  // namespace boicp
