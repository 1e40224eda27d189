// boicp-fusion-memory-bench: the peak memory of fusing one scan, as the
// fusion bomb does (the scan twice, at the same pose), side by side with
// the bound FusionBytesFloor puts on it. One configuration per process, so
// that the peak (VmHWM) belongs to it alone; bench/fusion_memory.sh runs a
// grid of them.
//
//   boicp-fusion-memory-bench --data DIR [--index I] --resolution M
//                             [--max-range M] [--threads T]

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "boicp/io/scan_folder.hpp"
#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/mapping/map_assembly.hpp"

namespace {

struct Options {
  std::string data;
  size_t index = 0;
  double resolution = 0.2;
  double max_range = 0.0;
  int threads = 1;
};

// A /proc/self/status field in MB (VmRSS now, VmHWM the peak).
double StatusMegabytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind(field + ":", 0) == 0) {
      std::istringstream in(line.substr(field.size() + 1));
      double kilobytes = 0.0;
      in >> kilobytes;
      return kilobytes / 1024.0;
    }
  }
  throw std::runtime_error("/proc/self/status has no " + field);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"One scan's peak fusion memory against its estimate"};
  app.add_option("--data", o.data, "Scan folder")->required();
  app.add_option("--index", o.index, "Which scan of the folder");
  app.add_option("--resolution", o.resolution, "Leaf size, metres");
  app.add_option("--max-range", o.max_range, "Ray cut, metres (0 = none)");
  app.add_option("--threads", o.threads, "Fusion threads");
  CLI11_PARSE(app, argc, argv);
  try {
    const boicp::ScanFolder folder = boicp::ReadScanFolder(o.data);
    if (o.index >= folder.scans.size()) throw std::runtime_error("--index beyond the folder");
    const boicp::ScanSource& scan = folder.scans[o.index];
    const boicp::Points points = boicp::LoadPointCloud(scan.path, scan.load).points;

    boicp::MapBuildSettings settings;
    settings.occupancy.resolution = o.resolution;
    settings.occupancy.max_range = o.max_range;
    settings.fusion_threads = o.threads;
    const double cells = boicp::RayCellsBound(boicp::ProfileRanges(points),
                                              scan.sensor_origin.norm(), settings.occupancy);
    const double bound_mb = boicp::FusionBytesFloor({cells}) / (1024.0 * 1024.0);

    const double before_mb = StatusMegabytes("VmRSS");
    boicp::FuseScans({scan, scan}, {boicp::Transform::Identity(), boicp::Transform::Identity()},
                     settings, {});
    const double fusion_mb = StatusMegabytes("VmHWM") - before_mb;

    // The cells one scan actually marks, counted after the peak was read.
    boicp::OccupancyMap map(settings.occupancy);
    const boicp::ScanUpdate update =
        map.ComputeUpdate(points, boicp::Transform::Identity(), scan.sensor_origin, o.threads);
    const double marked = static_cast<double>(update.FreeCells() + update.OccupiedCells());
    map.ApplyUpdate(update);
    const double megabyte = 1024.0 * 1024.0;
    std::printf(
        "{\"data\": \"%s\", \"points\": %zu, \"resolution\": %g, \"max_range\": %g, "
        "\"threads\": %d, \"cells_marked\": %.0f, \"cells_bound\": %.0f, "
        "\"fusion_mb\": %.1f, \"bound_mb\": %.1f, \"tree_mb\": %.1f, \"update_mb\": %.1f}\n",
        o.data.c_str(), points.size(), o.resolution, o.max_range, o.threads, marked, cells,
        fusion_mb, bound_mb, static_cast<double>(map.TreeBytes()) / megabyte,
        static_cast<double>(update.Bytes()) / megabyte);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "boicp-fusion-memory-bench: %s\n", e.what());
    return 2;
  }
}
