#include "boicp/mapping/map_up.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>

#include "boicp/icp/surface_normals.hpp"
#include "boicp/registration/auto_settings.hpp"

namespace boicp {
namespace {

// Bounds the cost of scoring: the candidates and the normals they are
// scored against are strided subsets, so the result stays deterministic.
constexpr size_t kMaxCandidates = 600;
constexpr size_t kMaxScored = 30000;

std::string Degrees(double radians) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", radians * 180.0 / M_PI);
  return text;
}

// The prior up direction, and where it came from.
std::pair<Eigen::Vector3d, std::string> PriorUp(const std::vector<Transform>& poses,
                                                const UpDetectionOptions& options) {
  if (options.sensor_up && !poses.empty()) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Transform& T : poses)
      sum += T.topLeftCorner<3, 3>() * options.sensor_up->normalized();
    if (sum.norm() > 1e-6 * static_cast<double>(poses.size())) {
      return {sum.normalized(), "the sensors' up"};
    }
  }
  return {Eigen::Vector3d::UnitZ(), "the map's z"};
}

// A cell's neighbours within three cells span its surface patch.
std::vector<Eigen::Vector3d> CellNormals(const Points& centres, double resolution) {
  return EstimateSurfaceNormals(NearestNeighborIndex(centres), 3.0 * resolution, /*threads=*/1);
}

// Area-weighted fraction of the normals within the tolerance of `axis`
// (either sign).
double Support(const Eigen::Vector3d& axis, const std::vector<Eigen::Vector3d>& normals,
               const std::vector<double>& weights, size_t stride, double cos_tolerance) {
  double inside = 0.0, total = 0.0;
  for (size_t i = 0; i < normals.size(); i += stride) {
    total += weights[i];
    if (std::abs(normals[i].dot(axis)) >= cos_tolerance) inside += weights[i];
  }
  return total > 0.0 ? inside / total : 0.0;
}

// The principal axis of the normals within the tolerance of `axis`: the
// plane family's mean normal, free of the candidate's own noise.
Eigen::Vector3d RefineAxis(const Eigen::Vector3d& axis, const std::vector<Eigen::Vector3d>& normals,
                           const std::vector<double>& weights, double cos_tolerance) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < normals.size(); ++i) {
    if (std::abs(normals[i].dot(axis)) >= cos_tolerance) {
      scatter += weights[i] * normals[i] * normals[i].transpose();
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Eigen::Vector3d refined = solver.eigenvectors().col(2);
  return refined.dot(axis) < 0.0 ? Eigen::Vector3d(-refined) : refined;
}

}  // namespace

std::optional<Eigen::Vector3d> SensorUp(const std::optional<SensorKind>& set, CloudFormat format) {
  const std::optional<DeclaredSensor> declared = DeclareSensor(set, format);
  if (!declared || declared->kind == SensorKind::kOther) return std::nullopt;
  if (declared->kind == SensorKind::kDepthCamera) return Eigen::Vector3d(0, -1, 0);
  return Eigen::Vector3d::UnitZ();
}

UpDirection DetectUp(const Points& centres, const std::vector<double>& sizes, double resolution,
                     const std::vector<Transform>& poses, const UpDetectionOptions& options) {
  const auto [prior, prior_name] = PriorUp(poses, options);
  UpDirection out;
  out.up = prior;
  const std::string fallback = prior_name == "the map's z" ? "map z" : prior_name;
  if (centres.size() < 100 || !(resolution > 0.0)) {
    out.reason = "up = " + fallback + ": too few occupied cells to find horizontal surfaces";
    return out;
  }

  const std::vector<Eigen::Vector3d> normals = CellNormals(centres, resolution);
  // A cell weighs its area; one without a surface normal (too few
  // neighbours, or on a line) weighs nothing.
  std::vector<double> weights(normals.size(), 1.0);
  for (size_t i = 0; i < normals.size(); ++i) {
    if (i < sizes.size()) weights[i] = sizes[i] * sizes[i];
    if (normals[i].isZero()) weights[i] = 0.0;
  }
  const double cos_tolerance = std::cos(options.normal_tolerance);
  const double cos_prior = std::cos(options.max_prior_angle);
  const size_t candidate_stride = std::max<size_t>(1, normals.size() / kMaxCandidates);
  const size_t scored_stride = std::max<size_t>(1, normals.size() / kMaxScored);

  Eigen::Vector3d best = prior;
  double best_support = -1.0;
  for (size_t i = 0; i < normals.size(); i += candidate_stride) {
    if (std::abs(normals[i].dot(prior)) < cos_prior) continue;
    const double support = Support(normals[i], normals, weights, scored_stride, cos_tolerance);
    if (support > best_support) {
      best_support = support;
      best = normals[i];
    }
  }
  if (best_support < options.min_support) {
    out.reason = "up = " + fallback + ": no family of horizontal surfaces within " +
                 Degrees(options.max_prior_angle) + " degrees of " + prior_name;
    return out;
  }
  Eigen::Vector3d up = RefineAxis(best, normals, weights, cos_tolerance);
  if (up.dot(prior) < 0.0) up = -up;
  out.up = up;
  out.detected = true;
  out.support = Support(up, normals, weights, 1, cos_tolerance);
  char text[160];
  std::snprintf(text, sizeof text,
                "up from the horizontal surfaces (%.0f %% of the cells), %s degrees from %s",
                100.0 * out.support,
                Degrees(std::acos(std::clamp(up.dot(prior), -1.0, 1.0))).c_str(),
                prior_name.c_str());
  out.reason = text;
  return out;
}

}  // namespace boicp
