#include "boicp/registration/auto_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/icp/preprocess.hpp"
#include "boicp/util/parallel_for.hpp"
#include "boicp/util/percentile.hpp"

namespace boicp {
namespace {

// The rules below were read off the shared KITTI, 7-Scenes and bunny scans
// (bench/README.md, "Automatic settings"); each is a ratio to the scene's own
// size, so no rule names a sensor's range or a dataset.

// Search voxel = RMS radius / 25. Coarse enough that ICP's basin (3 voxels)
// spans the gaps between a scene's main surfaces, fine enough that about 25
// voxels across the scene keep its shape: 0.6 m for a street, 4 cm for a
// room, 2.5 mm for a 6 cm object.
constexpr double kRadiusPerVoxel = 25.0;
// A doubtful answer is searched for again 4 voxels coarser (RMS radius / 6):
// the scale at which a small object's views, or low-overlap views, still
// share their coarse shape.
constexpr double kRetryVoxelScale = 4.0;
// Translation box half-width, the search box being centred where the two
// centroids meet. A view from a cone (a camera, a scanner facing an object)
// that turns or moves sees other parts of the scene, so the centroids of two
// views can lie as far apart as the scene's RMS radius. An all-around scan
// that moves keeps seeing most of what it saw, so its centroid follows the
// motion, a quarter of the radius; on level ground its height barely changes,
// so z gets only the minimum: two search voxels, which every axis gets at
// least so that it still holds a basin or two.
constexpr double kConeTranslationPerRadius = 1.0;
constexpr double kAllAroundTranslationPerRadius = 0.25;
constexpr double kMinTranslationBoundVoxels = 2.0;
// A spinning LiDAR sees every side of its origin; a depth camera or a scanner
// of objects sees one cone, which makes their directions from the origin
// alike (a mean unit direction over 0.5), whatever their azimuths. A ring
// with up to a third of it blocked (an operator's back, a side mount, a
// vehicle's own body) is still a ring: points spread evenly over 240
// degrees of azimuth have a mean direction of 0.41.
constexpr int kAzimuthSectors = 36;
constexpr int kAllAroundSectors = 24;
constexpr double kMaxAllAroundDirection = 0.5;  // norm of the mean unit direction
// Ground: the largest plane below the origin, holding at least a sixth of the
// points, with its normal within 15 degrees of +z. A car's roll and pitch then
// stay within a few degrees of the scan's own.
constexpr double kMinGroundShare = 1.0 / 6.0;
constexpr double kMaxGroundTilt = 15.0 * M_PI / 180.0;
constexpr double kLevelRollPitchBound = 0.2;  // radians, for two scans on level ground
constexpr int kPlaneTrials = 200;
// Points measured (random, seeded): statistics of 20,000 points differ from
// those of the whole cloud by far less than the rules' precision.
constexpr size_t kMeasuredPoints = 20000;
// Scans of one scene in one unit differ in extent and in point spacing by a
// few times at most (a corridor against an open yard, a near view against a
// far one); a factor over 20 in both is a millimetre cloud against a metre one.
constexpr double kUnitMismatch = 20.0;
constexpr size_t kSpacingQueries = 1000;
// Far returns (through a window or an open door, off rain or dust) lie many
// times farther from the scene's middle than its typical point, and a few
// percent of them would set the RMS radius, and with it every rule above.
// Points beyond 12 median distances from the coordinate-wise median point are
// set aside before measuring: clean scans reach 8 (a KITTI street's far
// end), 4 (a 7-Scenes room) and 3 (the bunny).
constexpr double kFarReturnMedians = 12.0;

double MeanDirection(const Points& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Point& p : points) {
    if (p.norm() > 0.0) sum += p.normalized();
  }
  return points.empty() ? 0.0 : sum.norm() / static_cast<double>(points.size());
}

double AzimuthCoverageDeg(const Points& points) {
  std::vector<bool> seen(kAzimuthSectors, false);
  for (const Point& p : points) {
    const double azimuth = std::atan2(p.y(), p.x()) + M_PI;  // [0, 2 pi]
    const int sector =
        std::min(kAzimuthSectors - 1, static_cast<int>(azimuth / (2.0 * M_PI) * kAzimuthSectors));
    seen[static_cast<size_t>(sector)] = true;
  }
  return 360.0 * static_cast<double>(std::count(seen.begin(), seen.end(), true)) / kAzimuthSectors;
}

struct GroundPlane {
  double tilt = 0.0;   // radians between its normal and +z
  double depth = 0.0;  // metres from the origin down to it
};

// RANSAC (seeded) for the near-horizontal plane with the most points within
// `tolerance` metres. Returns it when it holds kMinGroundShare of the points
// and lies below the origin.
std::optional<GroundPlane> FindGround(const Points& points, double tolerance, uint64_t seed) {
  if (points.size() < 3) return std::nullopt;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  size_t best_count = 0;
  Eigen::Vector3d best_normal = Eigen::Vector3d::UnitZ();
  double best_offset = 0.0;
  for (int trial = 0; trial < kPlaneTrials; ++trial) {
    const Point& a = points[pick(rng)];
    const Point& b = points[pick(rng)];
    const Point& c = points[pick(rng)];
    Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.norm() < 1e-12) continue;
    normal.normalize();
    if (normal.z() < 0) normal = -normal;
    if (std::acos(std::min(1.0, normal.z())) > kMaxGroundTilt) continue;
    const double offset = -normal.dot(a);  // plane: normal . p + offset = 0
    const size_t count =
        static_cast<size_t>(std::count_if(points.begin(), points.end(), [&](const Point& p) {
          return std::abs(normal.dot(p) + offset) < tolerance;
        }));
    if (count > best_count) {
      best_count = count;
      best_normal = normal;
      best_offset = offset;
    }
  }
  // The origin must lie above the plane (offset > 0 with the normal up).
  if (static_cast<double>(best_count) < kMinGroundShare * static_cast<double>(points.size()) ||
      best_offset <= 0.0) {
    return std::nullopt;
  }
  return GroundPlane{std::acos(std::min(1.0, best_normal.z())), best_offset};
}

// The lower of the two middle values: an element of the sample, never a
// mean of two.
double LowerMedian(std::vector<double> values) { return Percentile(std::move(values), 0.5); }

// How many times the coordinates of `other` would have to be scaled to match
// `first`'s scale, when both the RMS radius and the point spacing say so by
// more than kUnitMismatch; 0 when the clouds may share units.
double UnitMismatch(const CloudStatistics& first, const CloudStatistics& other) {
  if (!(first.spacing > 0.0 && other.spacing > 0.0)) return 0.0;
  const double radii = first.rms_radius / other.rms_radius;
  const double spacings = first.spacing / other.spacing;
  const bool larger = radii > kUnitMismatch && spacings > kUnitMismatch;
  const bool smaller = radii < 1.0 / kUnitMismatch && spacings < 1.0 / kUnitMismatch;
  return larger || smaller ? std::sqrt(radii * spacings) : 0.0;
}

// A factor as a user would type it: the nearest power of ten when it is
// within a quarter of one (millimetres, centimetres, inches are not).
std::string FactorText(double factor) {
  const double decade = std::pow(10.0, std::round(std::log10(factor)));
  char text[32];
  std::snprintf(text, sizeof text, "%.4g",
                std::abs(factor / decade - 1.0) < 0.25 ? decade : factor);
  return text;
}

// Why ChooseSettings took the sensor it took, in the words of its rules:
// what was declared, else the least all-around of the clouds; then, for a
// LiDAR, the ground its rotation box relies on.
std::string SensorReason(const std::vector<CloudStatistics>& stats,
                         const std::optional<DeclaredSensor>& declared, SensorKind sensor,
                         bool level) {
  const auto least_around = std::min_element(
      stats.begin(), stats.end(), [](const CloudStatistics& a, const CloudStatistics& b) {
        return std::make_pair(a.all_around, -a.mean_direction) <
               std::make_pair(b.all_around, -b.mean_direction);
      });
  char text[160];
  if (declared) {
    std::snprintf(text, sizeof text, "%s", declared->why.c_str());
  } else if (least_around->mean_direction > kMaxAllAroundDirection) {
    std::snprintf(text, sizeof text, "one-sided view (mean direction %.2f)",
                  least_around->mean_direction);
  } else {
    std::snprintf(text, sizeof text, "ring covering %.0f deg", least_around->azimuth_coverage_deg);
    if (!least_around->all_around) {
      return std::string(text) + " (a LiDAR's covers 240 or more)";
    }
  }
  std::string reason = text;
  if (sensor != SensorKind::kLidar) return reason;
  if (!level) return reason + ", no ground plane below the origin in every scan";
  std::vector<double> depths;
  for (const CloudStatistics& s : stats) depths.push_back(s.ground_depth);
  std::snprintf(text, sizeof text, ", ground plane %.2f m below the origin",
                LowerMedian(std::move(depths)));
  return reason + text;
}

void CheckSharedUnits(const std::vector<CloudStatistics>& stats) {
  const CloudStatistics& first = stats.front();
  for (size_t k = 1; k < stats.size(); ++k) {
    const double factor = UnitMismatch(first, stats[k]);
    if (factor == 0.0) continue;
    char scales[256];
    std::snprintf(scales, sizeof scales,
                  "RMS radius %.3g and point spacing %.3g in the first, %.3g and %.3g in the "
                  "other",
                  first.rms_radius, first.spacing, stats[k].rms_radius, stats[k].spacing);
    throw InputError("the scans differ in scale by a factor of about " +
                     FactorText(std::max(factor, 1.0 / factor)) + " (" + scales +
                     "): do they share units? Convert one to the other's units (for a pair, " +
                     "boicp register --scale-source " + FactorText(1.0 / factor) +
                     " multiplies the source's coordinates by " + FactorText(1.0 / factor) + ")");
  }
}

// Where far returns begin: a sphere about the coordinate-wise median point,
// which a few percent of far points cannot drag as they drag a centroid.
struct FarReturnGate {
  Point centre;
  double max_distance;
  bool Excludes(const Point& p) const { return (p - centre).norm() > max_distance; }
};

FarReturnGate FarReturnGateOf(const Points& points) {
  std::vector<double> x, y, z;
  for (const Point& p : points) {
    x.push_back(p.x());
    y.push_back(p.y());
    z.push_back(p.z());
  }
  const Point centre(LowerMedian(std::move(x)), LowerMedian(std::move(y)),
                     LowerMedian(std::move(z)));
  std::vector<double> distances;
  for (const Point& p : points) distances.push_back((p - centre).norm());
  // Half the points in one place give no scale to measure "far" by.
  const double median = LowerMedian(std::move(distances));
  return {centre,
          median > 0.0 ? kFarReturnMedians * median : std::numeric_limits<double>::infinity()};
}

// Median distance from a point to its nearest other point, over
// kSpacingQueries random points (seeded) against the whole cloud.
double PointSpacing(PointSpan cloud, uint64_t seed) {
  const NearestNeighborIndex tree(cloud.ToPoints(), /*neighbour_lists=*/false,
                                  NearestNeighborIndex::kFewQueriesLeafSize);
  std::vector<double> gaps;
  std::vector<size_t> indices;
  std::vector<double> squared;
  for (const Point& p : RandomSubsample(cloud, kSpacingQueries, seed)) {
    tree.KNearest(p, 2, std::numeric_limits<double>::infinity(), indices, squared);
    if (indices.size() == 2) gaps.push_back(std::sqrt(squared[1]));
  }
  return gaps.empty() ? 0.0 : LowerMedian(gaps);
}

// The finest refinement level: two point spacings, the finest voxel that
// still averages a few points, but between a sixteenth and a quarter of the
// search voxel, so the pyramid is two to four levels deep.
double RefineVoxel(double voxel, double spacing) {
  return std::clamp(2.0 * spacing, voxel / 16.0, voxel / 4.0);
}

}  // namespace

CloudStatistics MeasureCloud(PointSpan cloud, uint64_t seed) {
  const std::string advice =
      " to choose settings from; give --voxel and --translation-bounds (or --fixed-settings)";
  if (cloud.size() < kMinPointsForSettings) {
    throw InputError("a cloud has " + std::to_string(cloud.size()) + " points, too few" + advice);
  }
  const Points sample = RandomSubsample(cloud, kMeasuredPoints, seed);
  const FarReturnGate gate = FarReturnGateOf(sample);
  Points points;
  points.reserve(sample.size());
  for (const Point& p : sample) {
    if (!gate.Excludes(p)) points.push_back(p);
  }
  CloudStatistics stats;
  stats.points = cloud.size();
  stats.far_returns = static_cast<size_t>(
      std::count_if(cloud.begin(), cloud.end(), [&](const Point& p) { return gate.Excludes(p); }));
  std::vector<double> ranges;
  ranges.reserve(points.size());
  for (const Point& p : points) ranges.push_back(p.norm());
  stats.rms_radius = RmsRadius(points);
  if (!(stats.rms_radius > 1e-9)) {
    throw InputError("a cloud has all its points in one place, nothing" + advice);
  }
  stats.range_p95 = Percentile(ranges, 0.95);
  stats.spacing = PointSpacing(cloud, seed);
  stats.mean_direction = MeanDirection(points);
  stats.azimuth_coverage_deg = AzimuthCoverageDeg(points);
  stats.all_around = stats.mean_direction <= kMaxAllAroundDirection &&
                     stats.azimuth_coverage_deg >= kAllAroundSectors * (360.0 / kAzimuthSectors);
  const double voxel = stats.rms_radius / kRadiusPerVoxel;
  // The settings serve both budgets, and the fixed budget's answers depend on
  // the order of the points the ground's seeded draws pick from.
  if (const std::optional<GroundPlane> ground =
          FindGround(VoxelDownsample(points, voxel / 2, CellOrder::kOpen3d), voxel / 2, seed + 1)) {
    stats.ground_tilt = ground->tilt;
    stats.ground_depth = ground->depth;
  }
  return stats;
}

std::optional<DeclaredSensor> DeclareSensor(const std::optional<SensorKind>& set,
                                            CloudFormat format) {
  if (set) return DeclaredSensor{*set, "set by --sensor"};
  if (format == CloudFormat::kKittiBin) {
    return DeclaredSensor{SensorKind::kLidar, "KITTI .bin scans (a spinning LiDAR)"};
  }
  if (format == CloudFormat::kDepthPng)
    return DeclaredSensor{SensorKind::kDepthCamera, "depth images"};
  return std::nullopt;
}

ChosenSettings ChooseSettings(const std::vector<CloudStatistics>& stats,
                              const std::optional<DeclaredSensor>& declared) {
  if (stats.empty()) throw InputError("automatic settings need at least one cloud");
  CheckSharedUnits(stats);
  std::vector<double> radii, ranges, spacings, tilts;
  bool all_around = true, level = true;
  for (const CloudStatistics& s : stats) {
    radii.push_back(s.rms_radius);
    ranges.push_back(s.range_p95);
    spacings.push_back(s.spacing);
    all_around = all_around && s.all_around;
    level = level && s.ground_tilt.has_value();
    if (s.ground_tilt) tilts.push_back(*s.ground_tilt);
  }
  ChosenSettings chosen;
  for (const CloudStatistics& s : stats) chosen.far_returns.push_back(s.far_returns);
  if (declared) {
    chosen.sensor = declared->kind;
  } else if (all_around) {
    chosen.sensor = SensorKind::kLidar;
  }
  chosen.sensor_reason = SensorReason(stats, declared, chosen.sensor, level);
  chosen.voxel = LowerMedian(radii) / kRadiusPerVoxel;
  chosen.point_spacing = LowerMedian(spacings);
  const double radius = LowerMedian(radii);
  chosen.translation_bounds.setConstant(
      (all_around ? kAllAroundTranslationPerRadius : kConeTranslationPerRadius) * radius);
  if (all_around && level) chosen.translation_bounds.z() = 0.0;  // raised to the minimum below
  chosen.translation_bounds = chosen.translation_bounds.cwiseMax(
      Eigen::Vector3d::Constant(kMinTranslationBoundVoxels * chosen.voxel));
  if (chosen.sensor == SensorKind::kLidar && level) {
    // Both scans on level ground: their roll and pitch differ by at most
    // the two tilts, so a small box holds them; yaw stays free.
    const double tilt = *std::max_element(tilts.begin(), tilts.end());
    const double roll_pitch = std::max(kLevelRollPitchBound, 2.0 * tilt);
    chosen.rotation_bounds = {roll_pitch, roll_pitch, M_PI};
  } else {
    chosen.rotation_bounds = {M_PI, M_PI / 2, M_PI};
  }
  // A third of the search voxel keeps walls and kerbs a few cells thick.
  chosen.map_resolution = chosen.voxel / 3.0;
  // The sparse far tail of a scan costs most of the ray casting (cost grows
  // with the ray's length) and carries the least structure.
  chosen.map_max_range = LowerMedian(ranges);
  return chosen;
}

ChosenSettings ChooseSettingsForClouds(const std::vector<PointSpan>& clouds,
                                       const std::optional<DeclaredSensor>& declared, uint64_t seed,
                                       size_t max_clouds, int threads) {
  if (clouds.empty()) throw InputError("automatic settings need at least one cloud");
  const size_t count = std::min(std::max<size_t>(max_clouds, 1), clouds.size());
  std::vector<CloudStatistics> stats(count);
  ParallelFor(count, threads, [&](size_t k) {
    const size_t index = count == 1 ? 0 : k * (clouds.size() - 1) / (count - 1);
    stats[k] = MeasureCloud(clouds[index], seed + index);
  });
  return ChooseSettings(stats, declared);
}

std::vector<std::string> ApplyChosenSettings(const ChosenSettings& chosen, BoIcpConfig& config) {
  const auto automatic = [&](const std::string& field) {
    return std::find(config.automatic.begin(), config.automatic.end(), field) !=
           config.automatic.end();
  };
  // The presets' voxels keep their ratio (A and B search 7/6 coarser than C).
  const double preset_scale = PresetConfig(config.preset).voxel / PresetConfig("C").voxel;
  std::vector<std::string> set;
  for (const std::string& field : kAutoRegistrationFields) {
    if (!automatic(field)) continue;
    set.push_back(field);
    if (field == "voxel") {
      config.voxel = chosen.voxel * preset_scale;
      config.retry_voxel = kRetryVoxelScale * config.voxel;
    }
    if (field == "refine_voxel")
      config.refine_voxel = RefineVoxel(config.voxel, chosen.point_spacing);
    // Tighter than ICP's 3-voxel gate, so a looser but larger overlap (a
    // view slid along a wall) does not outscore the true one.
    if (field == "objective_truncation") config.objective_truncation = 1.5 * config.voxel;
    if (field == "translation_bounds") config.translation_bounds = chosen.translation_bounds;
    if (field == "rotation_bounds") config.rotation_bounds = chosen.rotation_bounds;
  }
  config.automatic.clear();
  return set;
}

}  // namespace boicp

namespace boicp {

std::string DescribeSettings(const BoIcpConfig& config, const std::vector<std::string>& auto_fields,
                             const ChosenSettings& chosen) {
  const auto mark = [&](const std::string& field) {
    return std::find(auto_fields.begin(), auto_fields.end(), field) != auto_fields.end() ? " (auto)"
                                                                                         : "";
  };
  char text[768];
  std::snprintf(text, sizeof text,
                "preset %s, %s search, sensor %s (%s): voxel %.3g m%s, refine voxel %.3g m%s, "
                "translation bounds %.3g,%.3g,%.3g m%s, rotation bounds %.3g,%.3g,%.3g rad%s, "
                "%d threads, seed %llu",
                config.preset.c_str(), SearchModeName(config.mode).c_str(),
                SensorKindName(chosen.sensor).c_str(), chosen.sensor_reason.c_str(), config.voxel,
                mark("voxel"), config.EffectiveRefineVoxel(), mark("refine_voxel"),
                config.translation_bounds[0], config.translation_bounds[1],
                config.translation_bounds[2], mark("translation_bounds"), config.rotation_bounds[0],
                config.rotation_bounds[1], config.rotation_bounds[2], mark("rotation_bounds"),
                config.threads, static_cast<unsigned long long>(config.seed));
  return text;
}

std::vector<std::string> ChooseSettingsForPair(PointSpan source, PointSpan target,
                                               BoIcpConfig& config) {
  if (config.automatic.empty()) return {};
  return ApplyChosenSettings(
      ChooseSettingsForClouds({source, target}, DeclareSensor(config.sensor, CloudFormat::kAuto),
                              config.seed, 2, config.threads),
      config);
}

}  // namespace boicp
