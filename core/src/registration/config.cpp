#include "boicp/registration/config.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "boicp/util/types.hpp"

namespace boicp {

SearchMode ParseSearchMode(const std::string& name) {
  if (name == "nested") return SearchMode::kNested;
  if (name == "6dof") return SearchMode::kSixDof;
  throw InputError("unknown search mode '" + name + "' (expected nested or 6dof)");
}

std::string SearchModeName(SearchMode mode) {
  return mode == SearchMode::kNested ? "nested" : "6dof";
}

IcpObjective ParseIcpObjective(const std::string& name) {
  if (name == "point") return IcpObjective::kPointToPoint;
  if (name == "plane") return IcpObjective::kPointToPlane;
  throw InputError("unknown ICP objective '" + name + "' (expected point or plane)");
}

std::string IcpObjectiveName(IcpObjective objective) {
  return objective == IcpObjective::kPointToPoint ? "point" : "plane";
}

Budget ParseBudget(const std::string& name) {
  if (name == "auto") return Budget::kAuto;
  if (name == "fixed") return Budget::kFixed;
  throw InputError("unknown budget '" + name + "' (expected auto or fixed)");
}

std::string BudgetName(Budget budget) { return budget == Budget::kAuto ? "auto" : "fixed"; }

std::string SensorKindName(SensorKind kind) {
  switch (kind) {
    case SensorKind::kLidar:
      return "lidar";
    case SensorKind::kDepthCamera:
      return "depth camera";
    case SensorKind::kOther:
      break;
  }
  return "other";
}

std::optional<SensorKind> ParseSensorSetting(const std::string& name) {
  if (name == "auto" || name.empty()) return std::nullopt;
  if (name == "lidar") return SensorKind::kLidar;
  if (name == "depth") return SensorKind::kDepthCamera;
  if (name == "object") return SensorKind::kOther;
  throw InputError("unknown sensor '" + name + "' (expected lidar, depth, object or auto)");
}

std::string SensorSettingName(const std::optional<SensorKind>& sensor) {
  if (!sensor) return "auto";
  switch (*sensor) {
    case SensorKind::kLidar:
      return "lidar";
    case SensorKind::kDepthCamera:
      return "depth";
    case SensorKind::kOther:
      break;
  }
  return "object";
}

const std::vector<std::string> kAutoRegistrationFields = {
    "voxel", "refine_voxel", "objective_truncation", "translation_bounds", "rotation_bounds"};

Eigen::Vector3d SnapRotationBounds(const Eigen::Vector3d& bounds) {
  constexpr double kSnap = 1e-3;
  Eigen::Vector3d snapped = bounds;
  for (int axis : {0, 2}) {
    if (std::abs(snapped[axis] - M_PI) < kSnap) snapped[axis] = M_PI;
  }
  if (std::abs(snapped[1] - M_PI / 2) < kSnap) snapped[1] = M_PI / 2;
  return snapped;
}

void BoIcpConfig::MarkSet(const std::string& field) {
  automatic.erase(std::remove(automatic.begin(), automatic.end(), field), automatic.end());
}

BayesOptOptions RegistrationBayesOptOptions() {
  BayesOptOptions options;
  options.acquisition.random_candidates = 1000;
  return options;
}

double BoIcpConfig::EffectiveMaxCorrespondence() const {
  return max_correspondence_distance > 0.0 ? max_correspondence_distance : 3.0 * voxel;
}

double BoIcpConfig::EffectiveTruncation() const {
  return objective_truncation > 0.0 ? objective_truncation : 1.5 * voxel;
}

double BoIcpConfig::EffectiveRefineVoxel() const {
  return refine_voxel > 0.0 ? refine_voxel : voxel / 4.0;
}

double BoIcpConfig::EffectiveInlierDistance() const {
  return inlier_distance > 0.0 ? inlier_distance : 1.5 * EffectiveRefineVoxel();
}

RotationCoordinates BoIcpConfig::EffectiveRotationCoordinates() const {
  return rotation_coordinates.value_or(budget == Budget::kAuto
                                           ? RotationCoordinates::kRotationVector
                                           : RotationCoordinates::kEulerAngles);
}

BoIcpConfig PresetConfig(const std::string& name) {
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  BoIcpConfig config;
  config.preset = upper;
  if (upper == "A") {
    config.random_samples = 10;
    config.iterations = 20;
    config.voxel = 0.7;
  } else if (upper == "B") {
    config.random_samples = 20;
    config.iterations = 35;
    config.voxel = 0.7;
  } else if (upper == "C") {
    config.random_samples = 30;
    config.iterations = 60;
    config.voxel = 0.6;
  } else {
    throw InputError("unknown preset '" + name + "' (expected A, B or C)");
  }
  return config;
}

namespace {

void RequireValidConfig(bool ok, const std::string& message) {
  if (!ok) throw InputError("invalid config: " + message);
}

bool FiniteNonNegative(const Eigen::Vector3d& v) {
  return v.allFinite() && (v.array() >= 0.0).all();
}

}  // namespace

void ValidateConfig(const BoIcpConfig& c) {
  RequireValidConfig(c.random_samples >= 1, "random samples (N_r) must be at least 1");
  RequireValidConfig(c.iterations >= 0, "iterations (N) must not be negative");
  RequireValidConfig(std::isfinite(c.voxel) && c.voxel > 0.0,
                     "voxel must be a positive number of metres");
  RequireValidConfig(std::isfinite(c.retry_voxel) && c.retry_voxel >= 0.0,
                     "retry voxel must be >= 0 metres (0 = the search voxel)");
  RequireValidConfig(FiniteNonNegative(c.rotation_bounds),
                     "rotation bounds must be finite and non-negative (radians)");
  RequireValidConfig(FiniteNonNegative(c.translation_bounds),
                     "translation bounds must be finite and non-negative (metres)");
  RequireValidConfig(c.rotation_bounds.maxCoeff() > 0.0 || c.translation_bounds.maxCoeff() > 0.0,
                     "rotation and translation bounds are all zero: nothing to search");
  const Eigen::Vector3d rotation = SnapRotationBounds(c.rotation_bounds);
  RequireValidConfig(rotation[0] <= M_PI && rotation[2] <= M_PI,
                     "roll and yaw bounds must not exceed pi");
  RequireValidConfig(
      rotation[1] <= M_PI / 2,
      "pitch bound must not exceed pi/2 (larger pitches repeat rotations already covered)");
  RequireValidConfig(
      std::isfinite(c.max_correspondence_distance) && c.max_correspondence_distance >= 0.0,
      "max correspondence distance must be >= 0 (0 = 3 x voxel)");
  RequireValidConfig(std::isfinite(c.objective_truncation) && c.objective_truncation >= 0.0,
                     "objective truncation must be >= 0 (0 = 1.5 x voxel)");
  RequireValidConfig(c.icp_max_iterations >= 1, "ICP iterations must be at least 1");
  RequireValidConfig(c.finish_icp_iterations >= 1, "ICP finishing iterations must be at least 1");
  RequireValidConfig(c.refine_candidates >= 1, "refine candidates must be at least 1");
  RequireValidConfig(c.refine_max_iterations >= 1, "refinement ICP iterations must be at least 1");
  RequireValidConfig(
      std::isfinite(c.refine_voxel) && c.refine_voxel >= 0.0 && c.refine_voxel <= c.voxel,
      "refine voxel must be between 0 (auto) and the search voxel");
  RequireValidConfig(std::isfinite(c.inlier_distance) && c.inlier_distance >= 0.0,
                     "inlier distance must be >= 0 (0 = auto)");
  RequireValidConfig(std::isfinite(c.min_range) && std::isfinite(c.max_range) &&
                         c.min_range >= 0.0 && c.max_range >= 0.0 &&
                         (c.max_range == 0.0 || c.max_range > c.min_range),
                     "ranges must satisfy 0 <= min_range < max_range (max_range 0 = no limit)");
  RequireValidConfig(c.threads >= 1, "threads must be at least 1");
  for (const std::string& field : c.automatic) {
    RequireValidConfig(std::find(kAutoRegistrationFields.begin(), kAutoRegistrationFields.end(),
                                 field) != kAutoRegistrationFields.end(),
                       "'" + field + "' is not a setting that can be chosen automatically");
  }
}

}  // namespace boicp
