#pragma once
// One pair registration of a scan batch, as the daemon's workers and the
// one-shot `boicp map` command both run it: with the pair's own seed, centred
// on the scans' prior poses.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/map_pairs.hpp"
#include "boicp/mapping/pair_result.hpp"
#include "boicp/mapping/pose_graph.hpp"
#include "boicp/mapping/prepared_scan_cache.hpp"
#include "boicp/registration/auto_settings.hpp"
#include "boicp/registration/bo_icp.hpp"

namespace boicp {

/// Takes scans[pair.source] and scans[pair.target] from `prepared` (a cache
/// over `scans` whose method is job_config.method with job_config) and
/// registers them with that method, with job_config but seed
/// PairSeed(job_config.seed, pair), centred on `prior` when given, else on
/// PairPrior when both scans have a prior pose; scans adjacent in the batch
/// get identity as the guess (PairHints). job_config's settings must be final (ApplyBatchSettings).
/// Throws Cancelled when `stop_requested` fires, InputError when a scan does
/// not load, an index is out of range or the method is unknown,
/// std::runtime_error for engine failures.
PairResult RegisterBatchPair(const std::vector<ScanSource>& scans, const PairIndex& pair,
                             const BoIcpConfig& job_config, PreparedScanCache& prepared,
                             const std::function<bool()>& stop_requested = {},
                             const std::optional<Transform>& prior = std::nullopt);

/// The finest search or refinement voxel accepted, as a fraction of the
/// scans' extent: finer ones downsample nothing more, and only push voxel
/// keys towards their range.
constexpr double kMinVoxelOfExtent = 1e-5;

/// Throws InputError naming `voxel` or `refine_voxel` when the one the
/// config uses is under kMinVoxelOfExtent times `extent` (metres, the
/// farthest point of any scan from its frame's origin; 0 = unknown).
void RequireVoxelsFitExtent(const BoIcpConfig& config, double extent);

/// Which map settings a batch leaves to be chosen from its scans.
struct MapAutoFields {
  bool resolution = true;  // OccupancySettings::resolution, reported as "map_resolution"
  bool max_range = true;   // OccupancySettings::max_range, reported as "map_max_range"
};

/// A scan the batch's settings were measured on, and the points of it set
/// aside as far returns while measuring (CloudStatistics::far_returns).
struct MeasuredScan {
  size_t scan = 0;  // index into the batch's scans
  size_t far_returns = 0;
};

/// What ApplyBatchSettings chose, and from which scans.
struct BatchSettingsChoice {
  std::vector<std::string> fields;  // names of the fields it set
  std::vector<MeasuredScan> measured;
  SensorKind sensor = SensorKind::kOther;  // what the settings assumed, when measured
  std::string sensor_reason;               // why (ChosenSettings::sensor_reason)
};

/// Chooses, once for the whole batch, the fields of `config` still in
/// config.automatic and the map fields `map_auto` names, from up to 5 of the
/// scans spread evenly over the batch (so every pair, every shard and every
/// resume gets the same settings). Loads nothing, and measures no scan, when
/// nothing is automatic. Throws InputError when a scan does not load or is
/// too small to choose settings from.
BatchSettingsChoice ApplyBatchSettings(const std::vector<ScanSource>& scans, BoIcpConfig& config,
                                       OccupancySettings& occupancy, const MapAutoFields& map_auto);

/// The closing line of a batch: "2 of 40 pairs doubtful" (doubtful =
/// confidence below kTrustedFrom).
std::string DoubtfulSummary(int doubtful, int total);

/// A registered pair's translation error along one axis, as a fraction of
/// the inlier distance (bench/README.md, "Pose graph": measured on the
/// 7-Scenes drive, checked on KITTI).
constexpr double kPairErrorOfInlierDistance = 0.4;

/// Pose-graph options matching how RegisterBatchPair computed the
/// information matrices (correspondences within the inlier distance), with
/// each edge's error kPairErrorOfInlierDistance of it.
PoseGraphOptions BatchPoseGraphOptions(const BoIcpConfig& job_config);

}  // namespace boicp
