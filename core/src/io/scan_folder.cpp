#include "boicp/io/scan_folder.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>

#include "boicp/io/trajectory_io.hpp"
#include "boicp/util/parallel_for.hpp"
#include "boicp/util/text.hpp"
#include "io/io_readers.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;
using io_detail::FullListing;
using io_detail::IsBlankOrComment;
using io_detail::ParseNumber;
using io_detail::SplitFields;

bool IsDirectory(const fs::path& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

bool IsFile(const fs::path& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Regular files of `dir` whose lower-case name passes `keep`, in name order.
std::vector<fs::path> ListFiles(const fs::path& dir,
                                const std::function<bool(const std::string&)>& keep) {
  std::vector<fs::path> files;
  if (!IsDirectory(dir)) return files;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
    if (!IsFile(entry.path())) continue;
    if (keep(LowerCase(entry.path().filename().string()))) files.push_back(entry.path());
  }
  if (ec) throw InputError(dir.string() + ": cannot list (" + ec.message() + ")");
  std::sort(files.begin(), files.end(),
            [](const fs::path& a, const fs::path& b) { return a.filename() < b.filename(); });
  return files;
}

bool IsCloudFileName(const std::string& lower_name) {
  for (const char* ext : {".pcd", ".ply", ".xyz"}) {
    if (EndsWith(lower_name, ext)) return true;
  }
  return false;
}

bool IsSevenScenesDepthName(const std::string& lower_name) {
  return lower_name.rfind("frame-", 0) == 0 && EndsWith(lower_name, ".depth.png");
}

// The folder holding 7-Scenes depth frames: `root/depth` when it has them, else `root`.
fs::path SevenScenesDepthDir(const fs::path& root) {
  if (!ListFiles(root / "depth", IsSevenScenesDepthName).empty()) return root / "depth";
  return root;
}

ScanLayout DetectLayout(const fs::path& root) {
  if (!ListFiles(root / "velodyne", [](const std::string& n) {
         return EndsWith(n, ".bin");
       }).empty()) {
    return ScanLayout::kKitti;
  }
  if (IsFile(root / "depth.txt")) return ScanLayout::kTum;
  if (!ListFiles(SevenScenesDepthDir(root), IsSevenScenesDepthName).empty()) {
    return ScanLayout::kSevenScenes;
  }
  if (!ListFiles(root, IsCloudFileName).empty()) return ScanLayout::kCloudFiles;
  throw InputError(root.string() +
                   ": no scans found (expected velodyne/*.bin, depth.txt, frame-*.depth.png, "
                   "or .pcd/.ply/.xyz files)");
}

// Numeric rows of a side file: every non-blank, non-comment line, its fields parsed.
std::vector<std::vector<double>> ReadNumberRows(const fs::path& path) {
  std::ifstream in = io_detail::OpenOrThrow(path.string());
  std::vector<std::vector<double>> rows;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (IsBlankOrComment(line)) continue;
    std::vector<double> row;
    for (std::string_view field : SplitFields(line)) {
      const std::optional<double> value = ParseNumber(field);
      if (!value || !std::isfinite(*value)) {
        throw InputError(path.string() + ":" + std::to_string(number) + ": '" + std::string(field) +
                         "' is not a finite number");
      }
      row.push_back(*value);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

Transform TransformFromRow(const std::vector<double>& row) {
  Transform T = Transform::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) T(i, j) = row[static_cast<size_t>(4 * i + j)];
  }
  return T;
}

// Tr (T_cam0_velo) from a KITTI calib.txt: the "Tr:" line's 12 numbers.
Transform ReadKittiCalibTr(const fs::path& path) {
  std::ifstream in = io_detail::OpenOrThrow(path.string());
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.empty() || fields[0] != "Tr:") continue;
    const std::string where = path.string() + ":" + std::to_string(number);
    if (fields.size() != 13) throw InputError(where + ": Tr needs 12 numbers");
    std::vector<double> row;
    for (size_t k = 1; k < fields.size(); ++k) {
      const std::optional<double> value = ParseNumber(fields[k]);
      if (!value || !std::isfinite(*value)) {
        throw InputError(where + ": '" + std::string(fields[k]) + "' is not a finite number");
      }
      row.push_back(*value);
    }
    return TransformFromRow(row);
  }
  throw InputError(path.string() + ": no 'Tr:' line (velodyne to camera transform)");
}

// Rows of exactly `width` numbers, at least `needed` of them.
std::vector<std::vector<double>> ReadTable(const fs::path& path, size_t width, size_t needed,
                                           const std::string& what) {
  std::vector<std::vector<double>> rows = ReadNumberRows(path);
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != width) {
      throw InputError(path.string() + ": data line " + std::to_string(i + 1) + " has " +
                       std::to_string(rows[i].size()) + " numbers, expected " +
                       std::to_string(width) + " (" + what + ")");
    }
  }
  if (rows.size() < needed) {
    throw InputError(path.string() + ": " + std::to_string(rows.size()) + " lines for " +
                     std::to_string(needed) + " scans");
  }
  return rows;
}

FullListing ListKitti(const fs::path& root) {
  FullListing out;
  out.what = "velodyne/*.bin";
  const std::vector<fs::path> bins =
      ListFiles(root / "velodyne", [](const std::string& n) { return EndsWith(n, ".bin"); });
  if (bins.empty()) throw InputError((root / "velodyne").string() + ": no .bin scans");
  for (const fs::path& bin : bins) {
    ScanSource scan;
    scan.path = bin.string();
    scan.load.format = CloudFormat::kKittiBin;
    out.scans.push_back(std::move(scan));
  }
  const fs::path poses = root / "poses.txt", calib = root / "calib.txt";
  if (IsFile(poses)) {
    // poses.txt holds left-camera poses P_i; the velodyne pose relative to
    // the first velodyne frame is Tr^-1 * P_i * Tr (see the KITTI devkit).
    if (!IsFile(calib)) {
      throw InputError(calib.string() +
                       ": missing; needed to turn poses.txt (camera poses) into velodyne poses");
    }
    const Transform Tr = ReadKittiCalibTr(calib);
    const Transform Tr_inv = Tr.inverse();
    for (const std::vector<double>& row : ReadTable(poses, 12, bins.size(), "3x4 pose")) {
      if (out.reference_poses.size() == bins.size()) break;
      out.reference_poses.emplace_back(Tr_inv * TransformFromRow(row) * Tr);
    }
  }
  const fs::path times = root / "times.txt";
  if (IsFile(times)) {
    const std::vector<std::vector<double>> rows = ReadTable(times, 1, bins.size(), "seconds");
    for (size_t i = 0; i < bins.size(); ++i) out.scans[i].timestamp = rows[i][0];
  }
  return out;
}

std::optional<Intrinsics> TumCameraIntrinsics(std::string name) {
  name = LowerCase(name);
  if (name.find("freiburg1") != std::string::npos || name.find("fr1") != std::string::npos) {
    return Intrinsics{517.3, 516.5, 318.6, 255.3};
  }
  if (name.find("freiburg2") != std::string::npos || name.find("fr2") != std::string::npos) {
    return Intrinsics{520.9, 521.0, 325.1, 249.7};
  }
  if (name.find("freiburg3") != std::string::npos || name.find("fr3") != std::string::npos) {
    return Intrinsics{535.4, 539.2, 320.1, 247.6};
  }
  return std::nullopt;
}

Intrinsics ResolveTumIntrinsics(const fs::path& root, const ScanFolderOptions& options) {
  if (options.intrinsics) return *options.intrinsics;
  if (!options.tum_camera.empty()) {
    const std::string camera = LowerCase(options.tum_camera);
    if (camera != "fr1" && camera != "fr2" && camera != "fr3") {
      throw InputError("camera: '" + options.tum_camera + "' is not fr1, fr2 or fr3");
    }
    return *TumCameraIntrinsics(camera);
  }
  const std::string folder = fs::absolute(root).lexically_normal().filename().string();
  const std::optional<Intrinsics> from_name = TumCameraIntrinsics(
      folder.empty() ? fs::absolute(root).parent_path().filename().string() : folder);
  if (!from_name) {
    throw InputError(root.string() +
                     ": TUM folder name names no camera (freiburg1/2/3); give the camera "
                     "(fr1|fr2|fr3) or the intrinsics");
  }
  return *from_name;
}

// TUM's ground truth runs at the motion-capture rate: each scan takes the
// pose nearest in time, when one lies within 20 ms (TUM's associate.py default).
std::vector<std::optional<Transform>> NearestPoses(std::vector<TimedPose> truth,
                                                   const std::vector<ScanSource>& scans) {
  constexpr double kMaxGap = 0.02;  // seconds
  std::sort(truth.begin(), truth.end(),
            [](const TimedPose& a, const TimedPose& b) { return a.timestamp < b.timestamp; });
  std::vector<std::optional<Transform>> poses;
  for (const ScanSource& scan : scans) {
    const double t = *scan.timestamp;
    auto after =
        std::lower_bound(truth.begin(), truth.end(), t,
                         [](const TimedPose& p, double time) { return p.timestamp < time; });
    std::optional<Transform> pose;
    double gap = kMaxGap;
    for (auto it : {after, after == truth.begin() ? truth.end() : std::prev(after)}) {
      if (it != truth.end() && std::abs(it->timestamp - t) <= gap) {
        gap = std::abs(it->timestamp - t);
        pose = it->pose;
      }
    }
    poses.push_back(pose);
  }
  return poses;
}

FullListing ListTum(const fs::path& root, const ScanFolderOptions& options) {
  FullListing out;
  out.what = "depth.txt";
  const fs::path list = root / "depth.txt";
  if (!IsFile(list)) throw InputError(list.string() + ": no such file (TUM depth list)");
  DepthOptions depth;
  depth.intrinsics = ResolveTumIntrinsics(root, options);
  depth.depth_scale = options.depth_scale > 0.0 ? options.depth_scale : 5000.0;
  std::ifstream in = io_detail::OpenOrThrow(list.string());
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (IsBlankOrComment(line)) continue;
    const std::string where = list.string() + ":" + std::to_string(number);
    const std::vector<std::string_view> fields = SplitFields(line);
    const std::optional<double> stamp = fields.empty() ? std::nullopt : ParseNumber(fields.front());
    if (fields.size() != 2 || !stamp || !std::isfinite(*stamp)) {
      throw InputError(where + ": expected 'timestamp filename'");
    }
    ScanSource scan;
    scan.path = (root / std::string(fields[1])).string();
    if (!IsFile(scan.path)) throw InputError(where + ": " + scan.path + ": no such file");
    scan.load.format = CloudFormat::kDepthPng;
    scan.load.depth = depth;
    scan.timestamp = *stamp;
    out.scans.push_back(std::move(scan));
  }
  if (out.scans.empty()) throw InputError(list.string() + ": lists no depth images");
  const fs::path truth = root / "groundtruth.txt";
  if (IsFile(truth))
    out.reference_poses = NearestPoses(ReadTumTrajectory(truth.string()), out.scans);
  return out;
}

FullListing ListSevenScenes(const fs::path& root, const ScanFolderOptions& options) {
  FullListing out;
  const fs::path depth_dir = SevenScenesDepthDir(root);
  out.what = depth_dir == root ? "frame-*.depth.png" : "depth/frame-*.depth.png";
  const std::vector<fs::path> frames = ListFiles(depth_dir, IsSevenScenesDepthName);
  if (frames.empty()) throw InputError(depth_dir.string() + ": no frame-*.depth.png images");
  DepthOptions depth;
  if (options.intrinsics) {
    depth.intrinsics = options.intrinsics;
  } else {
    const fs::path file = root / "camera-intrinsics.txt";
    if (!IsFile(file)) {
      throw InputError(file.string() + ": no such file; give the intrinsics (fx,fy,cx,cy)");
    }
    depth.intrinsics = ReadIntrinsicsFile(file.string());
  }
  depth.depth_scale = options.depth_scale > 0.0 ? options.depth_scale : 1000.0;
  const fs::path pose_dir = IsDirectory(root / "pose") ? root / "pose" : depth_dir;
  const bool has_poses = !ListFiles(pose_dir, [](const std::string& n) {
                            return n.rfind("frame-", 0) == 0 && EndsWith(n, ".pose.txt");
                          }).empty();
  for (const fs::path& frame : frames) {
    ScanSource scan;
    scan.path = frame.string();
    scan.load.format = CloudFormat::kDepthPng;
    scan.load.depth = depth;
    out.scans.push_back(std::move(scan));
    if (!has_poses) continue;
    // frame-000123.depth.png -> frame-000123.pose.txt (camera to world, 4x4).
    const std::string name = frame.filename().string();
    const fs::path pose = pose_dir / (name.substr(0, name.size() - 10) + ".pose.txt");
    if (!IsFile(pose)) throw InputError(pose.string() + ": no such file (pose of " + name + ")");
    out.reference_poses.emplace_back(ReadTransformFile(pose.string()));
  }
  return out;
}

FullListing ListCloudFiles(const fs::path& root) {
  FullListing out;
  const std::vector<fs::path> files = ListFiles(root, IsCloudFileName);
  if (files.empty()) throw InputError(root.string() + ": no .pcd, .ply or .xyz files");
  std::set<std::string> extensions;
  for (const fs::path& file : files) extensions.insert(LowerCase(file.extension().string()));
  if (extensions.size() > 1) {
    std::string list;
    for (const std::string& ext : extensions) list += (list.empty() ? "" : ", ") + ext;
    throw InputError(root.string() + ": mixes point formats (" + list +
                     "); keep one format per folder");
  }
  out.what = "*" + *extensions.begin();
  for (const fs::path& file : files) {
    ScanSource scan;
    scan.path = file.string();
    scan.load.format = DetectCloudFormat(file.string());
    out.scans.push_back(std::move(scan));
  }
  return out;
}

void ValidateSelection(const ScanFolderOptions& options) {
  if (options.first < 0) throw InputError("first: must be >= 0");
  if (options.stride < 1) throw InputError("stride: must be >= 1");
  if (options.count < 0) throw InputError("count: must be >= 0 (0 = all)");
  if (options.depth_scale < 0.0 || !std::isfinite(options.depth_scale)) {
    throw InputError("depth scale: must be > 0 (0 = the layout's)");
  }
}

std::string LayoutTitle(ScanLayout layout) {
  switch (layout) {
    case ScanLayout::kKitti:
      return "KITTI sequence";
    case ScanLayout::kTum:
      return "TUM RGB-D sequence";
    case ScanLayout::kSevenScenes:
      return "7-Scenes sequence";
    case ScanLayout::kCloudFiles:
      return "point-cloud files";
    case ScanLayout::kBag:
      return "bag";
    case ScanLayout::kAuto:
      break;
  }
  return "scans";
}

// The scans of a full listing of `where` that options' first, stride and
// count select.
ScanFolder Select(FullListing all, const ScanFolderOptions& options, const std::string& where,
                  ScanLayout layout) {
  ScanFolder folder;
  folder.layout = layout;
  const int total = static_cast<int>(all.scans.size());
  if (options.first >= total) {
    throw InputError("first: " + std::to_string(options.first) + " is beyond the " +
                     std::to_string(total) + " scans of " + where);
  }
  for (int i = options.first; i < total; i += options.stride) {
    if (options.count > 0 && static_cast<int>(folder.scans.size()) == options.count) break;
    const size_t k = static_cast<size_t>(i);
    ScanSource scan = std::move(all.scans[k]);
    const std::optional<Transform> pose =
        all.reference_poses.empty() ? std::nullopt : all.reference_poses[k];
    if (options.poses_as_priors) scan.prior_pose = pose;
    folder.scans.push_back(std::move(scan));
    folder.reference_poses.push_back(pose);
  }
  folder.description = LayoutTitle(folder.layout) + ", " + std::to_string(folder.scans.size()) +
                       " of " + std::to_string(total) + " scans (" + all.what + ")";
  return folder;
}

}  // namespace

ScanLayout ParseScanLayout(const std::string& name) {
  const std::string n = LowerCase(name);
  if (n == "auto") return ScanLayout::kAuto;
  if (n == "kitti") return ScanLayout::kKitti;
  if (n == "tum") return ScanLayout::kTum;
  if (n == "7scenes") return ScanLayout::kSevenScenes;
  if (n == "files") return ScanLayout::kCloudFiles;
  if (n == "bag") return ScanLayout::kBag;
  throw InputError("layout: '" + name + "' is not auto, kitti, tum, 7scenes, files or bag");
}

std::string ScanLayoutName(ScanLayout layout) {
  switch (layout) {
    case ScanLayout::kAuto:
      return "auto";
    case ScanLayout::kKitti:
      return "kitti";
    case ScanLayout::kTum:
      return "tum";
    case ScanLayout::kSevenScenes:
      return "7scenes";
    case ScanLayout::kCloudFiles:
      return "files";
    case ScanLayout::kBag:
      return "bag";
  }
  return "auto";
}

ScanFolder ReadScanFolder(const std::string& path, const ScanFolderOptions& options) {
  ValidateSelection(options);
  if (options.layout == ScanLayout::kBag ||
      (options.layout == ScanLayout::kAuto && IsBagPath(path))) {
    ScanFolderOptions bag_options = options;
    bag_options.poses_as_priors |= !options.bag.odometry_topic.empty();
    return Select(io_detail::ListBagScans(path, options.bag), bag_options, path, ScanLayout::kBag);
  }
  if (options.bag.Any()) {
    throw InputError(path +
                     ": bag options (topic, odometry topic, start, duration, min "
                     "interval) need a bag (.bag, .db3, .mcap or a ROS 2 bag folder)");
  }
  const fs::path root(path);
  std::error_code ec;
  if (!fs::exists(root, ec)) throw InputError(path + ": no such folder");
  if (!IsDirectory(root)) throw InputError(path + ": is not a folder");

  const ScanLayout layout =
      options.layout == ScanLayout::kAuto ? DetectLayout(root) : options.layout;
  FullListing all;
  switch (layout) {
    case ScanLayout::kKitti:
      all = ListKitti(root);
      break;
    case ScanLayout::kTum:
      all = ListTum(root, options);
      break;
    case ScanLayout::kSevenScenes:
      all = ListSevenScenes(root, options);
      break;
    case ScanLayout::kCloudFiles:
    case ScanLayout::kAuto:
    case ScanLayout::kBag:
      all = ListCloudFiles(root);
      break;
  }

  return Select(std::move(all), options, path, layout);
}

ScanFolder ReadScanList(const std::vector<std::string>& paths, const ScanFolderOptions& options) {
  ValidateSelection(options);
  if (paths.empty()) throw InputError("the list of scans is empty");
  FullListing all;
  std::set<std::string> extensions;
  for (const std::string& path : paths) {
    if (!IsFile(path)) throw InputError(path + ": no such file");
    ScanSource scan;
    scan.path = path;
    scan.load.format = DetectCloudFormat(path);
    if (scan.load.format == CloudFormat::kDepthPng) {
      if (!options.intrinsics || !(options.depth_scale > 0.0)) {
        throw InputError(path + ": a depth image needs the intrinsics and the depth scale");
      }
      scan.load.depth.intrinsics = options.intrinsics;
      scan.load.depth.depth_scale = options.depth_scale;
    }
    extensions.insert(LowerCase(fs::path(path).extension().string()));
    all.scans.push_back(std::move(scan));
  }
  for (const std::string& ext : extensions) all.what += (all.what.empty() ? "*" : ", *") + ext;
  return Select(std::move(all), options, "the list", ScanLayout::kCloudFiles);
}

void CheckScansLoad(const std::vector<ScanSource>& scans, int threads) {
  // LoadPointCloud's InputError already names the file and the problem, and
  // ParallelFor rethrows the first scan's in the given order.
  ParallelFor(scans.size(), threads,
              [&](size_t k) { LoadPointCloud(scans[k].path, scans[k].load); });
}

}  // namespace boicp
