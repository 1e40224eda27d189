// boicp-fusion-bench: scans fused per second on a real drive, OctoMap's own
// serial insertion (how OccupancyMap fused before it ray cast scans itself)
// side by side with FuseScans at each thread count, in interleaved rounds so
// that machine load hits every variant alike. Checks that every variant
// writes the same .bt bytes.
//
//   boicp-fusion-bench --data DIR [--count N] [--threads 1,2] [--rounds R]
//                      [--resolution M] [--max-range M] [--out DIR]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "boicp/io/scan_folder.hpp"
#include "boicp/mapping/map_assembly.hpp"
#include "boicp/util/percentile.hpp"

namespace {

namespace fs = std::filesystem;
using boicp::Median;
using boicp::Point;
using boicp::Transform;

struct Options {
  std::string data;
  int count = 10;
  std::vector<int> threads = {1, 2};
  int rounds = 3;
  double resolution = 0.2;
  double max_range = 0.0;
  std::string out = "/tmp/boicp-fusion-bench";
};

std::vector<int> ParseInts(const std::string& text) {
  std::vector<int> values;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) values.push_back(std::stoi(item));
  return values;
}

Options ParseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--data")
      o.data = value;
    else if (flag == "--count")
      o.count = std::stoi(value);
    else if (flag == "--threads")
      o.threads = ParseInts(value);
    else if (flag == "--rounds")
      o.rounds = std::stoi(value);
    else if (flag == "--resolution")
      o.resolution = std::stod(value);
    else if (flag == "--max-range")
      o.max_range = std::stod(value);
    else if (flag == "--out")
      o.out = value;
    else
      throw std::runtime_error("unknown flag " + flag);
  }
  if (o.data.empty()) throw std::runtime_error("--data DIR is required");
  return o;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// OctoMap's insertPointCloud(discretize = true, lazy_eval = true) on every
// scan, then the .bt: the plain fusion the batched one is measured against.
double FuseWithOctoMapInsertion(const std::vector<boicp::ScanSource>& scans,
                                const std::vector<Transform>& poses,
                                const boicp::OccupancySettings& s, const std::string& bt_path) {
  const auto start = std::chrono::steady_clock::now();
  octomap::OcTree tree(s.resolution);
  tree.setProbHit(s.prob_hit);
  tree.setProbMiss(s.prob_miss);
  tree.setClampingThresMin(s.clamp_min);
  tree.setClampingThresMax(s.clamp_max);
  for (size_t i = 0; i < scans.size(); ++i) {
    const boicp::Points points = boicp::LoadPointCloud(scans[i].path, scans[i].load).points;
    const Eigen::Matrix3d R = poses[i].topLeftCorner<3, 3>();
    const Eigen::Vector3d t = poses[i].topRightCorner<3, 1>();
    octomap::Pointcloud cloud;
    cloud.reserve(points.size());
    for (const Point& p : points) {
      const Point q = R * p + t;
      cloud.push_back(static_cast<float>(q.x()), static_cast<float>(q.y()),
                      static_cast<float>(q.z()));
    }
    const Point origin = R * scans[i].sensor_origin + t;
    tree.insertPointCloud(
        cloud,
        octomap::point3d(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                         static_cast<float>(origin.z())),
        s.max_range > 0.0 ? s.max_range : -1.0, true, true);
  }
  tree.updateInnerOccupancy();
  std::ofstream out(bt_path, std::ios::binary | std::ios::trunc);
  tree.writeBinary(out);
  return Seconds(start);
}

double FuseWithFuseScans(const std::vector<boicp::ScanSource>& scans,
                         const std::vector<Transform>& poses, const boicp::OccupancySettings& s,
                         int threads, const std::string& bt_path) {
  const auto start = std::chrono::steady_clock::now();
  boicp::MapBuildSettings settings;
  settings.occupancy = s;
  settings.fusion_threads = threads;
  boicp::MapOutputPaths outputs;
  outputs.octomap_bt = bt_path;
  boicp::FuseScans(scans, poses, settings, outputs);
  return Seconds(start);
}

struct StageSeconds {
  double load = 0, ray_cast = 0, tree_update = 0;
};

// The serial fusion's stages, timed apart: loading, ray casting
// (OccupancyMap::ComputeUpdate) and the tree update (ApplyUpdate).
StageSeconds TimeStages(const std::vector<boicp::ScanSource>& scans,
                        const std::vector<Transform>& poses, const boicp::OccupancySettings& s) {
  StageSeconds seconds;
  boicp::OccupancyMap map(s);
  for (size_t i = 0; i < scans.size(); ++i) {
    auto start = std::chrono::steady_clock::now();
    const boicp::Points points = boicp::LoadPointCloud(scans[i].path, scans[i].load).points;
    seconds.load += Seconds(start);
    start = std::chrono::steady_clock::now();
    const boicp::ScanUpdate update = map.ComputeUpdate(points, poses[i], scans[i].sensor_origin, 1);
    seconds.ray_cast += Seconds(start);
    start = std::chrono::steady_clock::now();
    map.ApplyUpdate(update);
    seconds.tree_update += Seconds(start);
  }
  return seconds;
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = ParseOptions(argc, argv);
    boicp::ScanFolderOptions folder_options;
    folder_options.count = o.count;
    const boicp::ScanFolder folder = boicp::ReadScanFolder(o.data, folder_options);
    std::vector<Transform> poses;
    for (const auto& pose : folder.reference_poses) {
      if (!pose) throw std::runtime_error(o.data + ": a scan has no reference pose");
      poses.push_back(*pose);
    }
    fs::create_directories(o.out);
    boicp::OccupancySettings occupancy;
    occupancy.resolution = o.resolution;
    occupancy.max_range = o.max_range;
    const int scans = static_cast<int>(folder.scans.size());
    std::fprintf(stderr, "%s; resolution %.2f m, max range %.0f m, %d rounds\n",
                 folder.description.c_str(), o.resolution, o.max_range, o.rounds);

    std::map<std::string, std::vector<double>> seconds;
    std::vector<std::string> order = {"octomap insertPointCloud"};
    for (const int t : o.threads) order.push_back("FuseScans " + std::to_string(t) + " thread(s)");
    const std::string reference_bt = o.out + "/octomap.bt";
    bool identical = true;
    for (int round = 0; round < o.rounds; ++round) {
      seconds[order[0]].push_back(
          FuseWithOctoMapInsertion(folder.scans, poses, occupancy, reference_bt));
      for (size_t k = 0; k < o.threads.size(); ++k) {
        const std::string bt = o.out + "/fused_t" + std::to_string(o.threads[k]) + ".bt";
        seconds[order[k + 1]].push_back(
            FuseWithFuseScans(folder.scans, poses, occupancy, o.threads[k], bt));
        identical = identical && Slurp(bt) == Slurp(reference_bt);
      }
      std::fprintf(stderr, "round %d/%d done\n", round + 1, o.rounds);
    }
    const double base = Median(seconds[order[0]]);
    std::printf("| fusion of %d KITTI scans (%.2f m) | median s | scans/s | speed-up |\n", scans,
                o.resolution);
    std::printf("|---|---:|---:|---:|\n");
    for (const std::string& name : order) {
      const double s = Median(seconds[name]);
      std::printf("| %s | %.2f | %.2f | %.2fx |\n", name.c_str(), s, scans / s, base / s);
    }
    const StageSeconds stages = TimeStages(folder.scans, poses, occupancy);
    std::printf(
        "\nSerial FuseScans by stage (one more run): load %.2f s, ray casting %.2f s, "
        "tree update %.2f s\n",
        stages.load, stages.ray_cast, stages.tree_update);
    std::printf("\n.bt bytes identical across variants: %s\n", identical ? "yes" : "NO");
    return identical ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "boicp-fusion-bench: error: %s\n", e.what());
    return 2;
  }
}
