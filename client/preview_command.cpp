// `boicp preview`: a top-down PNG of an OctoMap, coloured by height, with an
// optional trajectory drawn over it (the same picture `boicp map` writes).

#include <iostream>

#include "boicp/io/trajectory_io.hpp"
#include "boicp/mapping/map_preview.hpp"
#include "cli_parsing.hpp"
#include "commands.hpp"
#include "run_command.hpp"

namespace boicp::cli {
namespace {

struct PreviewFlags {
  std::string map, out, trajectory;
  std::string sensor_up;  // "x,y,z" in the scan frame; empty = unknown
  int size = 1024;
};

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Poses T_map_scan from a .tum or .kitti trajectory file.
std::vector<Transform> ReadTrajectory(const std::string& path) {
  if (EndsWith(path, ".kitti")) return ReadKittiTrajectory(path);
  if (!EndsWith(path, ".tum")) {
    throw InputError(path + ": trajectory must end in .tum or .kitti");
  }
  std::vector<Transform> poses;
  for (const TimedPose& p : ReadTumTrajectory(path)) poses.push_back(p.pose);
  return poses;
}

int RunPreview(const PreviewFlags& f) {
  const std::vector<Transform> poses =
      f.trajectory.empty() ? std::vector<Transform>{} : ReadTrajectory(f.trajectory);
  PreviewOptions options;
  options.size_px = f.size;
  UpDetectionOptions up_options;
  up_options.sensor_up = ParseSensorUp(f.sensor_up);
  if (up_options.sensor_up && poses.empty()) throw InputError("--sensor-up: needs --trajectory");
  const UpDirection up = WriteMapPreview(f.map, poses, f.out, options, up_options);
  std::cerr << "wrote " << f.out << " (" << up.reason << ")\n";
  return kOk;
}

}  // namespace

CommandRunner AddPreviewCommand(CLI::App& app) {
  auto flags = std::make_shared<PreviewFlags>();
  app.add_option("MAP", flags->map, "OctoMap file (.bt or .ot)")->required();
  app.add_option("-o,--out", flags->out, "PNG to write")->required();
  app.add_option("--trajectory", flags->trajectory, "Trajectory to draw (.tum or .kitti)");
  app.add_option("--sensor-up", flags->sensor_up, kSensorUpHelp);
  app.add_option("--size", flags->size, "Longer side of the image (pixels, >= 64)")
      ->capture_default_str();
  return [flags] { return RunCommand("preview", [&] { return RunPreview(*flags); }); };
}

}  // namespace boicp::cli
