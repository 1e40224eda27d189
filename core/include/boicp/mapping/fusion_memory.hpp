#pragma once
// How much memory fusing scans into an OctoMap takes, bounded from how far
// each scan's points reach, the leaf size and the ray length, so that a map
// too fine for its scans' reach is refused before it is built.

#include <cstdint>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// How far a scan's points lie from its frame's origin, and in how many
/// directions, as counts in geometric range bins: enough to bound the cells
/// its rays cross at any leaf size and ray length without keeping the points.
struct RangeProfile {
  /// Bin i counts the points at RangeBinUpperEdge(i-1) to RangeBinUpperEdge(i)
  /// metres (bin 0 from 0); the last bin also holds every farther point.
  std::vector<uint32_t> counts;
  /// The same bins, counting rays: fine directions (kProfileRayDirections
  /// cells of equal solid angle around the origin) by their farthest point.
  /// Points along one ray, as a line seen end on, share its cells.
  std::vector<uint32_t> ray_counts;
  /// The same for coarse directions (kProfileDirections cells).
  std::vector<uint32_t> direction_counts;
  double max_range = 0.0;  // metres, the farthest point

  bool empty() const { return counts.empty(); }
};

/// Number of bins of a RangeProfile; each is 2^(1/8) times as far out as
/// the one before, from 1 cm to about 2700 km.
constexpr int kRangeProfileBins = 224;

/// Direction cells of a RangeProfile: 512 azimuths by 256 bands of equal
/// height in z, each about 0.56 degrees across; and for its rays 7200 by
/// 3600, about 0.05 degrees, finer than a scanner's spacing of its beams.
constexpr int kProfileDirections = 512 * 256;
constexpr int kProfileRayDirections = 7200 * 3600;

/// Upper edge of bin `bin` in metres.
double RangeBinUpperEdge(int bin);

/// The profile of `points` (scan frame, metres). Precondition: fewer than
/// 2^32 points.
RangeProfile ProfileRanges(const Points& points);

/// An upper estimate of the leaves one scan's rays cross, endpoints
/// included, when it is fused with `settings` (leaf size and ray cut), its
/// rays leaving from a sensor origin `origin_offset` metres from the frame
/// origin. In each shell of one leaf's thickness around the origin, a ray
/// crosses at most sqrt(3) leaves, the rays along one fine direction fill a
/// tube a few leaves across, a coarse direction covers about its width
/// there squared, and the shell holds 4 pi (k + 1)^2 (directions count only
/// when origin_offset is 0). bench/fusion_memory.sh compares it with the
/// leaves marked. Returns 0 for an empty profile.
double RayCellsBound(const RangeProfile& ranges, double origin_offset,
                     const OccupancySettings& settings);

/// Bytes FuseScans may hold per leaf its scans' rays cross: the tree's node
/// and a share of its parents, and the ray-cast cells of scans in flight.
constexpr double kFusionBytesPerCell = 100.0;

/// Estimated peak fusion memory of a batch in bytes: the most demanding of
/// `scan_cells` (RayCellsBound of each scan) alone, which any map of these
/// scans holds at once. Overlapping scans add less than their own bound; a
/// long drive also grows the tree, which FuseScans checks as it goes.
double FusionBytesFloor(const std::vector<double>& scan_cells);

/// Throws LimitExceeded, with the estimate and what to change, when the
/// FusionBytesFloor of `scans` fused with `settings` is over `max_bytes`
/// (0 = no limit). `profiles[i]` is scans[i]'s ProfileRanges; an empty
/// profile (a scan stored before profiles were) counts as nothing.
void RequireFusionWithinLimit(const std::vector<ScanSource>& scans,
                              const std::vector<RangeProfile>& profiles,
                              const OccupancySettings& settings, size_t max_bytes);

/// The farthest point of any profile from its frame's origin, metres.
double ProfilesExtent(const std::vector<RangeProfile>& profiles);

/// Loads every scan once, `threads` at a time, and returns its
/// ProfileRanges. Throws InputError naming the first scan, in order, that
/// does not load.
std::vector<RangeProfile> ProfileScans(const std::vector<ScanSource>& scans, int threads);

}  // namespace boicp
