#pragma once
// Reading a logged drive from a folder or a bag: the layout (KITTI odometry,
// TUM RGB-D, 7-Scenes, a folder of PCD/PLY/XYZ files, or a ROS 1 / ROS 2 bag)
// is detected from the files present, or forced, and turned into the
// batch's scan list.

#include <optional>
#include <string>
#include <vector>

#include "boicp/io/bag_scans.hpp"
#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/scan_source.hpp"

namespace boicp {

enum class ScanLayout { kAuto, kKitti, kTum, kSevenScenes, kCloudFiles, kBag };

/// Parses "auto", "kitti", "tum", "7scenes", "files", "bag". Throws InputError otherwise.
ScanLayout ParseScanLayout(const std::string& name);
std::string ScanLayoutName(ScanLayout layout);

struct ScanFolderOptions {
  ScanLayout layout = ScanLayout::kAuto;  // kAuto: detected from the files present
  /// Depth layouts: overrides the intrinsics file (7-Scenes) or the camera
  /// name (TUM). Required for TUM when the camera cannot be named.
  std::optional<Intrinsics> intrinsics;
  /// TUM camera "fr1", "fr2" or "fr3"; empty = from the folder name
  /// (rgbd_dataset_freiburg2_desk -> fr2).
  std::string tum_camera;
  /// Raw depth units per metre; 0 = the layout's (TUM 5000, 7-Scenes 1000).
  double depth_scale = 0.0;
  /// Use the folder's own poses (KITTI poses.txt + calib.txt, TUM
  /// groundtruth.txt, 7-Scenes frame-*.pose.txt) as priors for the pair searches. Off by default:
  /// they are then only reported as reference_poses, never used as the answer.
  bool poses_as_priors = false;
  int first = 0;   // index of the first scan kept (in name / time order)
  int stride = 1;  // keep every stride-th scan, >= 1
  int count = 0;   // at most this many scans; 0 = all
  /// Bags only: the topics and the time window (applied before first,
  /// stride and count). An odometry topic turns poses_as_priors on.
  BagScanSelection bag;
};

struct ScanFolder {
  ScanLayout layout = ScanLayout::kAuto;  // the layout used (never kAuto)
  std::vector<ScanSource> scans;          // acquisition order, after first/stride/count
  /// Per kept scan, the folder's own pose T_world_scan in the scan (sensor)
  /// frame when the folder has one; for evaluation, not for the answer.
  std::vector<std::optional<Transform>> reference_poses;
  std::string description;  // one line, e.g. "KITTI sequence, 10 scans (velodyne/*.bin)"
};

/// Lists the scans of `path`, a folder or a bag (IsBagPath). Throws
/// InputError naming the file and the problem when the folder is missing or
/// holds nothing recognisable, mixes point formats, lacks what its layout
/// needs (intrinsics, depth.txt), or a side file (poses, calib, times) is
/// malformed; for a bag, when it is malformed, has no PointCloud2 topic or
/// several and options.bag names none, or the window keeps no message.
/// Scans are not loaded here; a bag's are read for their header stamps.
ScanFolder ReadScanFolder(const std::string& path, const ScanFolderOptions& options = {});

/// The scans of a list of files, in the list's order, as ReadScanFolder
/// gives a folder's (layout kCloudFiles; options' first, stride and count
/// apply): each file's format from its extension, depth images with
/// options' intrinsics and depth scale (both required). Throws InputError
/// naming the file that is missing, of an unknown extension, or a depth
/// image without intrinsics or depth scale, or for an empty list.
ScanFolder ReadScanList(const std::vector<std::string>& paths,
                        const ScanFolderOptions& options = {});

/// Loads every scan once, on at most `threads` threads, and throws
/// InputError naming the first one in their order that does not load
/// (unreadable, truncated, no finite point). Run before uploading or
/// registering anything.
void CheckScansLoad(const std::vector<ScanSource>& scans, int threads);

}  // namespace boicp
