#include "field_conditions.hpp"

#include <cmath>
#include <random>
#include <utility>

#include "boicp/icp/preprocess.hpp"

namespace boicp::bench {
namespace {

constexpr double kFarReturnShare = 0.03;
constexpr double kFarReturnNearest = 15.0;  // RMS radii
constexpr double kFarReturnFarthest = 40.0;
constexpr double kSectorRad = M_PI / 2;
constexpr double kTiltRad = 25.0 * M_PI / 180.0;
const Point kFarOrigin(800.0, -600.0, 20.0);
const Point kGeoOrigin(452000.0, 5411000.0, 250.0);  // a UTM easting and northing

struct Named {
  FieldCondition condition;
  const char* name;
};
constexpr Named kConditions[] = {
    {FieldCondition::kClean, "clean"},
    {FieldCondition::kFarReturns, "far-returns"},
    {FieldCondition::kSector, "sector"},
    {FieldCondition::kQuarter, "quarter"},
    {FieldCondition::kTilt, "tilt"},
    {FieldCondition::kFarOrigin, "far-origin"},
    {FieldCondition::kGeoOrigin, "geo-origin"},
};

// Returns through a window or an open door: directions uniform on the
// sphere, ranges uniform between the two multiples of the scan's RMS radius.
void AddFarReturns(Points& points, std::mt19937_64& rng) {
  const double radius = RmsRadius(points);
  const auto count = static_cast<size_t>(kFarReturnShare * static_cast<double>(points.size()));
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> range(kFarReturnNearest * radius,
                                               kFarReturnFarthest * radius);
  for (size_t i = 0; i < count; ++i) {
    Point direction(gauss(rng), gauss(rng), gauss(rng));
    if (direction.norm() < 1e-12) continue;
    points.push_back(direction.normalized() * range(rng));
  }
}

// Azimuth about the sensor's z axis: the horizontal ring of a LiDAR, the
// image plane of a camera looking along z.
Points WithoutSector(const Points& points, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> start(-M_PI, M_PI);
  const double from = start(rng);
  Points kept;
  for (const Point& p : points) {
    const double offset = std::remainder(std::atan2(p.y(), p.x()) - from, 2.0 * M_PI);
    if (!(offset >= 0.0 && offset < kSectorRad)) kept.push_back(p);
  }
  return kept;
}

}  // namespace

FieldCondition ParseFieldCondition(const std::string& name) {
  for (const Named& n : kConditions) {
    if (name == n.name) return n.condition;
  }
  throw InputError("unknown field condition '" + name + "' (" + FieldConditionNames() + ")");
}

std::string FieldConditionName(FieldCondition condition) {
  for (const Named& n : kConditions) {
    if (condition == n.condition) return n.name;
  }
  return "clean";
}

std::string FieldConditionNames() {
  std::string names;
  for (const Named& n : kConditions) names += (names.empty() ? "" : "|") + std::string(n.name);
  return names;
}

Transform FieldPair::Expected(const Transform& T_target_source,
                              const Transform& perturbation) const {
  return target_motion * T_target_source * source_motion.inverse() * perturbation.inverse();
}

Point FieldPair::ErrorPoint(const Transform& perturbation) const {
  return perturbation.topLeftCorner<3, 3>() * source_motion.topRightCorner<3, 1>();
}

FieldPair ApplyFieldCondition(FieldCondition condition, Points source, Points target,
                              uint64_t seed) {
  std::mt19937_64 rng(seed);
  FieldPair out;
  switch (condition) {
    case FieldCondition::kClean:
      break;
    case FieldCondition::kFarReturns:
      AddFarReturns(source, rng);
      AddFarReturns(target, rng);
      break;
    case FieldCondition::kSector:
      source = WithoutSector(source, rng);
      break;
    case FieldCondition::kQuarter:
      source = RandomSubsample(source, source.size() / 4, rng());
      break;
    case FieldCondition::kTilt:
      out.source_motion.topLeftCorner<3, 3>() =
          Eigen::AngleAxisd(kTiltRad, Eigen::Vector3d::UnitX()).toRotationMatrix();
      break;
    case FieldCondition::kFarOrigin:
    case FieldCondition::kGeoOrigin:
      out.source_motion.topRightCorner<3, 1>() =
          condition == FieldCondition::kFarOrigin ? kFarOrigin : kGeoOrigin;
      out.target_motion = out.source_motion;
      break;
  }
  out.source = TransformPoints(out.source_motion, source);
  out.target = TransformPoints(out.target_motion, target);
  return out;
}

}  // namespace boicp::bench
