// `boicp demo-data`: writes a generated pair of scans of a synthetic street
// with the true transform, or a generated drive with its true poses, so the
// demo runs on a machine without real data.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <string>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/io/trajectory_io.hpp"
#include "commands.hpp"
#include "run_command.hpp"

namespace boicp::cli {
namespace {

// Each scan is about 3 MB of text; the cap keeps a typo from filling the disk.
constexpr int kMaxDriveScans = 10000;

struct DemoFlags {
  std::string out = "demo";
  uint64_t seed = 7;
  double yaw_deg = 135.0;
  int scans = 0;       // 0: the pair; otherwise a drive of this many scans
  bool loop = false;   // the drive comes back to its start
  bool drift = false;  // irregular spacing and sweeps that are not de-skewed
};

void WriteTransform(const std::string& path, const Transform& T) {
  std::ofstream file(path);
  file << std::setprecision(12);
  for (int i = 0; i < 4; ++i) {
    file << T(i, 0) << " " << T(i, 1) << " " << T(i, 2) << " " << T(i, 3) << "\n";
  }
  if (!file) throw InputError(path + ": cannot write");
}

// Digits of the largest scan index, at least 3, so that name order is scan order.
int IndexDigits(int num_scans) {
  int digits = 1;
  for (int n = num_scans - 1; n >= 10; n /= 10) ++digits;
  return std::max(digits, 3);
}

std::string ZeroPadded(int value, int digits) {
  const std::string text = std::to_string(value);
  return std::string(static_cast<size_t>(std::max(digits - static_cast<int>(text.size()), 0)),
                     '0') +
         text;
}

// scan_000.xyz, scan_001.xyz, ... (a folder `boicp map` and `submit` read in
// name order) and their true poses T_world_scan in truth.kitti. Scans are
// generated and written one at a time, so any length fits in memory.
void WriteDrive(const DemoFlags& f) {
  const SyntheticDrive drive(f.scans, f.seed, f.loop, f.drift);
  const int digits = IndexDigits(f.scans);
  std::vector<Transform> poses;
  for (int i = 0; i < drive.size(); ++i) {
    const SyntheticScan scan = drive.Scan(i);
    WriteXyz(f.out + "/scan_" + ZeroPadded(i, digits) + ".xyz", scan.points);
    poses.push_back(scan.T_world_scan);
  }
  std::ofstream truth(f.out + "/truth.kitti");
  WriteKittiTrajectory(truth, poses);
  if (!truth) throw InputError(f.out + "/truth.kitti: cannot write");
  std::cerr << "wrote " << f.scans << " scans (" << f.out << "/scan_*.xyz) and their true poses ("
            << f.out << "/truth.kitti)\n";
}

int RunDemoData(const DemoFlags& f) {
  if (f.loop && f.scans == 0) throw InputError("--loop needs --scans N (a drive)");
  if (f.drift && f.scans == 0) throw InputError("--drift needs --scans N (a drive)");
  std::filesystem::create_directories(f.out);
  if (f.scans != 0) {
    if (f.scans < 2) throw InputError("--scans must be 0 (a pair) or at least 2");
    if (f.scans > kMaxDriveScans) {
      throw InputError("--scans must be at most " + std::to_string(kMaxDriveScans));
    }
    WriteDrive(f);
    return kOk;
  }
  const Points world = MakeSyntheticStreet(f.seed);
  // The source sensor is 1.5 m further along the street and turned by yaw:
  // a pose no plain ICP from identity recovers.
  const Transform T_world_target = PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8});
  const Transform T_world_source =
      PoseFromYawTranslation(f.yaw_deg * M_PI / 180.0, {1.5, 0.3, 1.8});
  WriteXyz(f.out + "/target.xyz", SimulateScan(world, T_world_target, 35.0, 0.02, f.seed + 1));
  WriteXyz(f.out + "/source.xyz", SimulateScan(world, T_world_source, 35.0, 0.02, f.seed + 2));
  WriteTransform(f.out + "/truth.txt", T_world_target.inverse() * T_world_source);
  std::cerr << "wrote " << f.out << "/source.xyz, target.xyz and truth.txt (T_target_source)\n";
  return kOk;
}

}  // namespace

CommandRunner AddDemoDataCommand(CLI::App& app) {
  auto flags = std::make_shared<DemoFlags>();
  app.add_option("-o,--out", flags->out, "Output folder")->capture_default_str();
  app.add_option("--seed", flags->seed, "Scene seed")->capture_default_str();
  app.add_option("--yaw", flags->yaw_deg, "Yaw between the two scans (degrees)")
      ->capture_default_str();
  app.add_option("--scans", flags->scans,
                 "Write a drive of this many scans (scan_*.xyz, truth.kitti) instead of a pair")
      ->capture_default_str();
  app.add_flag("--loop", flags->loop,
               "With --scans: drive out along the street and back in the other lane, ending "
               "beside the start");
  app.add_flag("--drift", flags->drift,
               "With --scans: log the drive as a throttled LiDAR log is, 0.5-7 m and up to "
               "0.75 rad between scans, each swept while moving and not de-skewed, so that "
               "chained registration drifts");
  return [flags] { return RunCommand("demo-data", [&] { return RunDemoData(*flags); }); };
}

}  // namespace boicp::cli
