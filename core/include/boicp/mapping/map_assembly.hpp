#pragma once
// Map assembly, shared by the daemon and the one-shot map command: from the
// registered pairs of a batch to poses (chained, then optimised when loops
// close), then to an OctoMap, a merged cloud and trajectory files.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/scan_source.hpp"
#include "boicp/mapping/loop_candidates.hpp"
#include "boicp/mapping/map_stage.hpp"
#include "boicp/mapping/occupancy_map.hpp"
#include "boicp/mapping/pose_graph.hpp"
#include "boicp/mapping/untrusted_scans.hpp"

namespace boicp {

struct PoseEstimate {
  std::vector<Transform> poses;  // T_map_scan
  bool optimised = false;        // a pose graph was optimised (loops closed)
  int loop_closures = 0;
  /// Per constraint: used by the final poses (false for loop closures the
  /// optimisation pruned or, being doubtful, left out).
  std::vector<bool> kept;
  /// Per constraint: why it is not kept (OptimizedPoses::left_out_because).
  std::vector<std::string> left_out_because;
};

/// Chains the constraints (listed with the sequential chain first; trusted
/// ones before doubtful ones, see ChainPoses) into poses and, when some
/// close loops, optimises the pose graph with each edge weighted by its
/// confidence (OptimizePoseGraph). The map frame is scan 0's prior world
/// frame when scan 0 has a prior pose, else scan 0's own frame. Of several
/// drives (`drive_starts`, drives.hpp), one that no constraint joins to the
/// first is estimated on its own, in its first scan's frame (or prior world
/// frame). Throws InputError when the constraints leave a scan unreached
/// from its drive's first scan.
PoseEstimate EstimatePoses(const std::vector<ScanSource>& scans,
                           const std::vector<PairConstraint>& constraints,
                           const PoseGraphOptions& options,
                           const std::vector<int>& drive_starts = {});

struct MapBuildSettings {
  OccupancySettings occupancy;
  double cloud_voxel = 0.0;  // metres, merged-cloud voxel; 0 = occupancy.resolution
  /// Threads FuseScans ray casts each scan on (< 1 counts as 1). With more
  /// than one, the tree update of one scan also overlaps the ray casting of
  /// the next. The outputs are the same bytes whatever the count.
  int fusion_threads = 1;
  /// Heap bytes fusion may hold (0 = no limit): three quarters for the
  /// tree, a quarter for the ray-cast cells of the scans in flight. FuseScans throws
  /// LimitExceeded, naming --max-fusion-mb, rather than pass it.
  size_t max_fusion_bytes = 0;
  LoopSearch loops = LoopSearch::kAuto;  // whether the map looks for loop closures itself
  /// Whether a scan with no trusted pair is fused (UntrustedScans).
  UntrustedScans untrusted_scans = UntrustedScans::kLeaveOut;
};

/// Where to write each output; an empty path skips that output. Every file
/// is written to a staging file beside it and renamed (WriteFileAtomically), so
/// a reader never sees half a file.
struct MapOutputPaths {
  std::string octomap_bt, octomap_ot, trajectory_tum, trajectory_kitti, cloud_ply;
};

struct AssemblyProgress {
  MapStage stage = MapStage::kFusing;  // kFusing or kWriting
  int done = 0;
  int total = 0;
};

struct AssemblyCallbacks {
  std::function<void(const AssemblyProgress&)> progress;
  /// Polled between scans and inside each scan's ray casting, tree update
  /// and tree writes (from several threads: it must be thread-safe); true
  /// -> boicp::Cancelled.
  MapStopRequest stop_requested;
};

struct FusionSummary {
  size_t occupied_leaves = 0;
  size_t cloud_points = 0;
  size_t points_out_of_range = 0;  // beyond the map's key range: left out of the tree
  double seconds = 0.0;
};

/// Loads every scan, inserts it into the OctoMap at its pose with its sensor
/// origin, accumulates the merged cloud (points within max_range only), and
/// writes the requested outputs. Scans stream through: at most two are held
/// at once (one ray cast while the one before updates the tree), so memory
/// beyond the tree and the voxel-downsampled cloud does not grow with the
/// number of scans. Throws InputError for invalid settings or a
/// scan that no longer loads, Cancelled when stop_requested fires,
/// LimitExceeded past settings.max_fusion_bytes, and std::runtime_error
/// when an output cannot be written.
/// Writes outputs.trajectory_tum and outputs.trajectory_kitti, those that
/// are set, with one pose per scan. Throws std::runtime_error when a file
/// cannot be written.
void WriteTrajectories(const std::vector<ScanSource>& scans, const std::vector<Transform>& poses,
                       const MapOutputPaths& outputs);

/// Of several drives (`drive_starts`, drives.hpp), each drive's poses (map
/// frame) as STEM.tum and STEM.kitti, STEM = `stems`[drive], written
/// atomically. Precondition: one stem per drive, one pose per scan.
void WriteDriveTrajectories(const std::vector<ScanSource>& scans,
                            const std::vector<Transform>& poses,
                            const std::vector<int>& drive_starts,
                            const std::vector<std::string>& stems);

FusionSummary FuseScans(const std::vector<ScanSource>& scans, const std::vector<Transform>& poses,
                        const MapBuildSettings& settings, const MapOutputPaths& outputs,
                        const AssemblyCallbacks& callbacks = {});

}  // namespace boicp
