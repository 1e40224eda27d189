#include "boicp/mapping/fusion_memory.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "boicp/util/parallel_for.hpp"

namespace boicp {
namespace {

constexpr double kFirstEdge = 0.01;  // metres
constexpr double kBinsPerOctave = 8.0;
constexpr int kAzimuths = 512;
constexpr int kRayAzimuths = 7200;

int RangeBin(double range) {
  const double octaves = range > kFirstEdge ? std::log2(range / kFirstEdge) : 0.0;
  return std::min(static_cast<int>(octaves * kBinsPerOctave), kRangeProfileBins - 1);
}

// A point's direction as fractions in [0, 1): azimuth in equal steps, and
// z / range too (Archimedes), so that equal steps of both cut the sphere
// into cells of equal solid angle.
struct Direction {
  double azimuth;
  double height;
};

Direction DirectionOf(const Point& p, double range) {
  return {(std::atan2(p.y(), p.x()) + M_PI) / (2.0 * M_PI), (p.z() / range + 1.0) / 2.0};
}

// The cell of `direction` in a grid of `cells` equal solid angles, `azimuths`
// of them around.
uint32_t DirectionCell(const Direction& direction, int cells, int azimuths) {
  const int heights = cells / azimuths;
  const int a = std::clamp(static_cast<int>(direction.azimuth * azimuths), 0, azimuths - 1);
  const int h = std::clamp(static_cast<int>(direction.height * heights), 0, heights - 1);
  return static_cast<uint32_t>(a * heights + h);
}

// Rays alive across one shell: `points` points, along `rays` fine
// directions, and over `directions` coarse ones (< 0: directions unknown,
// each point its own ray).
struct ShellRays {
  double points = 0.0;
  double rays = 0.0;
  double directions = -1.0;
};

// Leaves in shells [first, last) that the rays `alive` can mark. Per shell
// k, a ray crosses at most sqrt(3) leaves; the rays of one fine direction
// run to leaf centres (OctoMap's discretised insertion), so they fill a tube
// (side + 2)^2 leaves across, side being the direction's width there in
// leaves; a coarse direction covers about sqrt(3) max(side, 1)^2 leaves; and
// the shell holds 4 pi (k + 1)^2.
double ShellCells(double first, double last, const ShellRays& alive) {
  const double per_points = std::sqrt(3.0) * alive.points;
  const double ray_width = std::sqrt(4.0 * M_PI / kProfileRayDirections);
  const double direction_width = std::sqrt(4.0 * M_PI / kProfileDirections);
  double cells = 0.0;
  for (double k = first; k < last; ++k) {
    double shell = std::min(per_points, 4.0 * M_PI * (k + 1.0) * (k + 1.0));
    if (alive.directions >= 0.0) {
      const double tube = ray_width * (k + 1.0) + 2.0;
      const double side = std::max(direction_width * (k + 1.0), 1.0);
      shell = std::min({shell, std::sqrt(3.0) * alive.rays * tube * tube,
                        std::sqrt(3.0) * alive.directions * side * side});
    }
    // Every bound but the points' grows with k: from here on that one holds.
    if (shell >= per_points) return cells + per_points * (last - k);
    cells += shell;
  }
  return cells;
}

}  // namespace

double RangeBinUpperEdge(int bin) { return kFirstEdge * std::exp2((bin + 1) / kBinsPerOctave); }

RangeProfile ProfileRanges(const Points& points) {
  RangeProfile profile;
  profile.counts.assign(kRangeProfileBins, 0);
  profile.ray_counts.assign(kRangeProfileBins, 0);
  profile.direction_counts.assign(kRangeProfileBins, 0);
  std::vector<int> farthest(kProfileDirections, -1);  // bin of each direction's farthest point
  // The fine grid is too large for an array: (direction, bin) keys, sorted,
  // give each direction's farthest bin last, in 8 bytes a point.
  std::vector<uint64_t> on_rays;
  on_rays.reserve(points.size());
  for (const Point& p : points) {
    const double range = p.norm();
    const int bin = RangeBin(range);
    profile.max_range = std::max(profile.max_range, range);
    ++profile.counts[static_cast<size_t>(bin)];
    if (range > 0.0) {
      const Direction direction = DirectionOf(p, range);
      int& far = farthest[DirectionCell(direction, kProfileDirections, kAzimuths)];
      far = std::max(far, bin);
      const uint64_t ray = DirectionCell(direction, kProfileRayDirections, kRayAzimuths);
      on_rays.push_back(ray * kRangeProfileBins + static_cast<uint64_t>(bin));
    } else {
      ++profile.ray_counts[0];  // a point at the origin: a ray of no length
    }
  }
  for (const int bin : farthest) {
    if (bin >= 0) ++profile.direction_counts[static_cast<size_t>(bin)];
  }
  std::sort(on_rays.begin(), on_rays.end());
  for (size_t i = 0; i < on_rays.size(); ++i) {
    const bool last_of_its_ray = i + 1 == on_rays.size() || on_rays[i + 1] / kRangeProfileBins !=
                                                                on_rays[i] / kRangeProfileBins;
    if (last_of_its_ray) ++profile.ray_counts[on_rays[i] % kRangeProfileBins];
  }
  return profile;
}

double RayCellsBound(const RangeProfile& ranges, double origin_offset,
                     const OccupancySettings& settings) {
  if (ranges.empty()) return 0.0;
  const double leaf = settings.resolution;
  double reach = ranges.max_range + origin_offset;
  if (settings.max_range > 0.0) reach = std::min(reach, settings.max_range);
  const double last_shell = std::ceil(reach / leaf) + 1.0;
  // Directions are seen from the frame origin, so they bound the rays only
  // when those leave from there.
  const bool directions_known = origin_offset == 0.0;

  // A point at range r from the frame origin lies at most r + offset from
  // the ray origin, so the rays that reach a shell are at most those of the
  // bins whose upper edge, plus the offset, lies beyond the shell.
  ShellRays alive;
  for (const uint32_t count : ranges.counts) alive.points += count;
  double cells = alive.points;  // each point's endpoint leaf
  if (directions_known) {
    alive.directions = 0.0;
    for (const uint32_t count : ranges.ray_counts) alive.rays += count;
    for (const uint32_t count : ranges.direction_counts) alive.directions += count;
  }
  double shell = 0.0;
  for (size_t bin = 0; bin < ranges.counts.size() && shell < last_shell; ++bin) {
    const double edge =
        std::min(RangeBinUpperEdge(static_cast<int>(bin)), ranges.max_range) + origin_offset;
    const double end = std::min(std::ceil(edge / leaf), last_shell);
    cells += ShellCells(shell, end, alive);
    shell = std::max(shell, end);
    alive.points -= ranges.counts[bin];
    if (directions_known) {
      alive.rays -= ranges.ray_counts[bin];
      alive.directions -= ranges.direction_counts[bin];
    }
  }
  return cells;
}

double FusionBytesFloor(const std::vector<double>& scan_cells) {
  double most = 0.0;
  for (const double cells : scan_cells) most = std::max(most, cells);
  return most * kFusionBytesPerCell;
}

void RequireFusionWithinLimit(const std::vector<ScanSource>& scans,
                              const std::vector<RangeProfile>& profiles,
                              const OccupancySettings& settings, size_t max_bytes) {
  if (max_bytes == 0) return;
  std::vector<double> cells;
  for (size_t i = 0; i < scans.size() && i < profiles.size(); ++i) {
    cells.push_back(RayCellsBound(profiles[i], scans[i].sensor_origin.norm(), settings));
  }
  const double needed = FusionBytesFloor(cells);
  if (needed <= static_cast<double>(max_bytes)) return;
  const size_t worst = static_cast<size_t>(
      std::distance(cells.begin(), std::max_element(cells.begin(), cells.end())));
  std::ostringstream message;
  message << "the map needs an estimated " << static_cast<long long>(needed / (1 << 20))
          << " MB to fuse scan " << worst << " alone (" << static_cast<long long>(cells[worst])
          << " cells at " << settings.resolution << " m leaves, rays ";
  if (settings.max_range > 0.0) {
    message << "cut at " << settings.max_range << " m";
  } else {
    message << "uncut";
  }
  message << "), over the fusion memory limit of " << (max_bytes >> 20)
          << " MB (--max-fusion-mb); coarsen the map resolution or shorten max_range";
  throw LimitExceeded(message.str());
}

double ProfilesExtent(const std::vector<RangeProfile>& profiles) {
  double extent = 0.0;
  for (const RangeProfile& profile : profiles) extent = std::max(extent, profile.max_range);
  return extent;
}

std::vector<RangeProfile> ProfileScans(const std::vector<ScanSource>& scans, int threads) {
  std::vector<RangeProfile> profiles(scans.size());
  // LoadPointCloud's InputError names the file and the problem, and
  // ParallelFor rethrows the first scan's in order.
  ParallelFor(scans.size(), threads, [&](size_t k) {
    profiles[k] = ProfileRanges(LoadPointCloud(scans[k].path, scans[k].load).points);
  });
  return profiles;
}

}  // namespace boicp
