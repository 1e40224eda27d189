#include "boicp/mapping/map_assembly.hpp"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include "boicp/icp/voxel_cloud.hpp"
#include "boicp/io/trajectory_io.hpp"
#include "boicp/mapping/drives.hpp"
#include "boicp/util/atomic_file.hpp"
#include "boicp/util/parallel_for.hpp"

namespace boicp {
namespace {

void Report(const AssemblyCallbacks& callbacks, MapStage stage, int done, int total) {
  if (callbacks.progress) callbacks.progress({stage, done, total});
}

void ThrowIfStopped(const AssemblyCallbacks& callbacks) {
  if (callbacks.stop_requested && callbacks.stop_requested()) throw Cancelled();
}

// Points no farther than max_range from the sensor origin (all when 0).
Points WithinRange(const Points& points, const Point& origin, double max_range) {
  if (max_range <= 0.0) return points;
  Points kept;
  kept.reserve(points.size());
  const double max_sq = max_range * max_range;
  for (const Point& p : points) {
    if ((p - origin).squaredNorm() <= max_sq) kept.push_back(p);
  }
  return kept;
}

// Scans loaded and ray cast ahead of the tree update (FuseScans).
constexpr int kFusionWindow = 4;

// One scan ready to fuse: its ray-cast cells and, when the merged cloud is
// wanted, its points within range (scan frame).
struct ScanForFusion {
  ScanUpdate update;
  Points cloud_points;
};

ScanForFusion PrepareScan(const OccupancyMap& map, const ScanSource& scan, const Transform& pose,
                          const MapBuildSettings& settings, bool want_cloud, int threads,
                          size_t max_update_bytes, const MapStopRequest& stop) {
  ScanForFusion prepared;
  // Kept whole so that its share of a decode budget lasts the ray casting.
  const LoadedCloud loaded = LoadPointCloud(scan.path, scan.load);
  const Points& points = loaded.points;
  prepared.update =
      map.ComputeUpdate(points, pose, scan.sensor_origin, threads, stop, max_update_bytes);
  if (want_cloud) {
    prepared.cloud_points = WithinRange(points, scan.sensor_origin, settings.occupancy.max_range);
  }
  return prepared;
}

// What passed the fusion memory limit, and what to change.
LimitExceeded FusionLimitError(const LimitExceeded& e, const MapBuildSettings& settings) {
  std::ostringstream message;
  message << "fusion needs more memory than its limit of " << (settings.max_fusion_bytes >> 20)
          << " MB (--max-fusion-mb): " << e.what() << " at " << settings.occupancy.resolution
          << " m leaves; coarsen the map resolution, shorten max_range or raise the limit";
  return LimitExceeded(message.str());
}

void WriteText(const std::string& path, const std::function<void(std::ostream&)>& write) {
  WriteFileAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::trunc);
    write(out);
    if (!out.flush()) throw std::runtime_error(tmp + ": write failed");
  });
}

// The poses of scans that `constraints` connect (every scan reached from
// scan 0).
PoseEstimate EstimateConnectedPoses(const std::vector<ScanSource>& scans,
                                    const std::vector<PairConstraint>& constraints,
                                    const PoseGraphOptions& options) {
  const Transform anchor =
      !scans.empty() && scans[0].prior_pose ? *scans[0].prior_pose : Transform::Identity();
  const ChainedPoses chained = ChainPoses(static_cast<int>(scans.size()), constraints, anchor);
  PoseEstimate estimate;
  estimate.loop_closures = chained.loop_closures;
  if (chained.loop_closures == 0) {
    estimate.poses = chained.poses;
    estimate.kept.assign(constraints.size(), true);
    estimate.left_out_because.assign(constraints.size(), "");
    return estimate;
  }
  OptimizedPoses optimised =
      OptimizePoseGraph(chained.poses, constraints, chained.in_tree, options);
  estimate.poses = std::move(optimised.poses);
  estimate.kept = std::move(optimised.kept);
  estimate.left_out_because = std::move(optimised.left_out_because);
  estimate.optimised = true;
  return estimate;
}

}  // namespace

PoseEstimate EstimatePoses(const std::vector<ScanSource>& scans,
                           const std::vector<PairConstraint>& constraints,
                           const PoseGraphOptions& options, const std::vector<int>& drive_starts) {
  const int num_scans = static_cast<int>(scans.size());
  if (drive_starts.empty()) return EstimateConnectedPoses(scans, constraints, options);
  std::vector<PairIndex> pairs;
  for (const PairConstraint& c : constraints) pairs.push_back(c.pair);
  const std::vector<int> part_of_scan = ConnectedParts(num_scans, pairs);
  std::map<int, std::vector<int>> parts;  // by their first scan
  for (int i = 0; i < num_scans; ++i) parts[part_of_scan[static_cast<size_t>(i)]].push_back(i);
  if (parts.size() == 1) return EstimateConnectedPoses(scans, constraints, options);

  // Each part on its own, in its first scan's frame: scans renumbered
  // within the part, and its constraints with them.
  PoseEstimate estimate;
  estimate.poses.assign(scans.size(), Transform::Identity());
  estimate.kept.assign(constraints.size(), false);
  estimate.left_out_because.assign(constraints.size(), "");
  for (const auto& [first, part] : parts) {
    if (first != 0 && DriveOf(drive_starts, first) == DriveOf(drive_starts, first - 1)) {
      throw InputError("pose chain: no chain of registered pairs reaches scan " +
                       std::to_string(first) + " from its drive's first scan");
    }
    std::vector<int> local(scans.size(), -1);
    std::vector<ScanSource> part_scans;
    for (const int i : part) {
      local[static_cast<size_t>(i)] = static_cast<int>(part_scans.size());
      part_scans.push_back(scans[static_cast<size_t>(i)]);
    }
    std::vector<PairConstraint> part_constraints;
    std::vector<size_t> index_of;
    for (size_t e = 0; e < constraints.size(); ++e) {
      if (local[static_cast<size_t>(constraints[e].pair.source)] < 0) continue;
      PairConstraint c = constraints[e];
      c.pair = {local[static_cast<size_t>(c.pair.source)],
                local[static_cast<size_t>(c.pair.target)]};
      part_constraints.push_back(std::move(c));
      index_of.push_back(e);
    }
    PoseEstimate part_estimate = EstimateConnectedPoses(part_scans, part_constraints, options);
    for (size_t k = 0; k < part.size(); ++k) {
      estimate.poses[static_cast<size_t>(part[k])] = part_estimate.poses[k];
    }
    for (size_t k = 0; k < index_of.size(); ++k) {
      estimate.kept[index_of[k]] = part_estimate.kept[k];
      estimate.left_out_because[index_of[k]] = std::move(part_estimate.left_out_because[k]);
    }
    estimate.loop_closures += part_estimate.loop_closures;
    estimate.optimised = estimate.optimised || part_estimate.optimised;
  }
  return estimate;
}

void WriteTrajectories(const std::vector<ScanSource>& scans, const std::vector<Transform>& poses,
                       const MapOutputPaths& outputs) {
  if (!outputs.trajectory_tum.empty()) {
    WriteText(outputs.trajectory_tum,
              [&](std::ostream& out) { WriteTumTrajectory(out, ScanTimestamps(scans), poses); });
  }
  if (!outputs.trajectory_kitti.empty()) {
    WriteText(outputs.trajectory_kitti,
              [&](std::ostream& out) { WriteKittiTrajectory(out, poses); });
  }
}

void WriteDriveTrajectories(const std::vector<ScanSource>& scans,
                            const std::vector<Transform>& poses,
                            const std::vector<int>& drive_starts,
                            const std::vector<std::string>& stems) {
  for (size_t d = 0; d < stems.size(); ++d) {
    const auto [first, end] = DriveScans(drive_starts, static_cast<int>(scans.size()), d);
    const auto from = static_cast<std::ptrdiff_t>(first), to = static_cast<std::ptrdiff_t>(end);
    MapOutputPaths paths;
    paths.trajectory_tum = stems[d] + ".tum";
    paths.trajectory_kitti = stems[d] + ".kitti";
    WriteTrajectories({scans.begin() + from, scans.begin() + to},
                      {poses.begin() + from, poses.begin() + to}, paths);
  }
}

FusionSummary FuseScans(const std::vector<ScanSource>& scans, const std::vector<Transform>& poses,
                        const MapBuildSettings& settings, const MapOutputPaths& outputs,
                        const AssemblyCallbacks& callbacks) {
  const auto start = std::chrono::steady_clock::now();
  if (poses.size() != scans.size()) {
    throw InputError("map assembly: " + std::to_string(poses.size()) + " poses for " +
                     std::to_string(scans.size()) + " scans");
  }
  // The tree takes most: a scan's cells are a small bitmap next to the tree
  // nodes they make. A quarter of the limit is shared by the scans in
  // flight: a window being applied and one being cast, each scan's cells
  // cast and then merged (twice its cap at most).
  const int threads = std::max(settings.fusion_threads, 1);
  const int window = std::min(threads, kFusionWindow);
  const size_t max_update_bytes = settings.max_fusion_bytes / (12 * static_cast<size_t>(window));
  OccupancyMap map(settings.occupancy, settings.max_fusion_bytes / 4 * 3);
  const double cloud_voxel =
      settings.cloud_voxel > 0.0 ? settings.cloud_voxel : settings.occupancy.resolution;
  VoxelAccumulator cloud(cloud_voxel);
  const bool want_cloud = !outputs.cloud_ply.empty();
  const int total = static_cast<int>(scans.size());
  size_t points_out_of_range = 0;  // counted by the one task that applies updates

  // A window of scans is applied to the tree, in scan order, while the next
  // window is loaded and ray cast, each of its scans on its own threads.
  // Whole scans are shared out rather than the rays of one scan, so a thread
  // that has applied its window goes on to a scan instead of waiting for its
  // part of one. The window is at most kFusionWindow scans: two windows of
  // ray-cast cells are held at once. Only the timing depends on the thread
  // count, never the tree. A stop request ends the ray casting, the tree
  // update and the tree writes from inside, so a large scan or map does not
  // hold a cancel or a drain back.
  const int ray_threads = std::max(threads / window, 1);
  const auto window_at = [&](int first) { return std::max(std::min(window, total - first), 0); };
  const auto prepare = [&](int i) {
    const auto index = static_cast<size_t>(i);
    return PrepareScan(map, scans[index], poses[index], settings, want_cloud, ray_threads,
                       max_update_bytes, callbacks.stop_requested);
  };
  try {
    std::vector<ScanForFusion> current(static_cast<size_t>(window_at(0)));
    ThrowIfStopped(callbacks);
    ParallelFor(current.size(), threads,
                [&](size_t k) { current[k] = prepare(static_cast<int>(k)); });
    for (int first = 0; first < total; first += window) {
      ThrowIfStopped(callbacks);
      const int next_first = first + window;
      std::vector<ScanForFusion> next(static_cast<size_t>(window_at(next_first)));
      ParallelFor(1 + next.size(), threads, [&](size_t task) {
        if (task > 0) {
          next[task - 1] = prepare(next_first + static_cast<int>(task) - 1);
          return;
        }
        for (size_t k = 0; k < current.size(); ++k) {
          map.ApplyUpdate(current[k].update, callbacks.stop_requested);
          points_out_of_range += current[k].update.PointsOutOfRange();
          if (want_cloud) {
            cloud.Add(current[k].cloud_points, poses[static_cast<size_t>(first) + k]);
          }
        }
      });
      for (size_t k = 1; k <= current.size(); ++k) {
        Report(callbacks, MapStage::kFusing, first + static_cast<int>(k), total);
      }
      current = std::move(next);
    }
  } catch (const LimitExceeded& e) {
    throw FusionLimitError(e, settings);
  }

  ThrowIfStopped(callbacks);
  Report(callbacks, MapStage::kWriting, 0, 1);
  FusionSummary summary;
  summary.points_out_of_range = points_out_of_range;
  summary.occupied_leaves = map.OccupiedLeaves();
  // The .ot keeps full probabilities, so it goes before the .bt conversion.
  // A stop request is honoured during and between outputs too: each write
  // is atomic, so a stopped job leaves whole files, and its rerun rewrites
  // them all.
  if (!outputs.octomap_ot.empty()) {
    WriteFileAtomically(outputs.octomap_ot, [&](const std::string& tmp) {
      map.WriteFull(tmp, callbacks.stop_requested);
    });
  }
  ThrowIfStopped(callbacks);
  if (!outputs.octomap_bt.empty()) {
    WriteFileAtomically(outputs.octomap_bt, [&](const std::string& tmp) {
      map.WriteBinary(tmp, callbacks.stop_requested);
    });
  }
  ThrowIfStopped(callbacks);
  WriteTrajectories(scans, poses, outputs);
  ThrowIfStopped(callbacks);
  if (want_cloud) {
    const Points merged = cloud.Centroids();
    summary.cloud_points = merged.size();
    WriteFileAtomically(outputs.cloud_ply,
                        [&](const std::string& tmp) { WritePlyPoints(tmp, merged); });
  }
  Report(callbacks, MapStage::kWriting, 1, 1);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace boicp
