// `boicp export JOB --format F -o FILE`: downloads a finished job's map or
// trajectory, and for an OctoMap also writes a top-down preview PNG.

#include <cstdio>
#include <filesystem>
#include <map>

#include "boicp/io/trajectory_io.hpp"
#include "boicp/mapping/map_preview.hpp"
#include "boicp/mapping/map_up.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "boicp/util/atomic_file.hpp"
#include "cli_parsing.hpp"
#include "commands.hpp"
#include "remote_options.hpp"

namespace boicp::cli {
namespace {

namespace fs = std::filesystem;

struct ExportFlags {
  RemoteFlags remote;
  std::string job_id, format, output;
  std::string sensor_up;  // "x,y,z" in the scan frame; empty = unknown
  bool preview = true;
  uint32_t drive = 0;  // a trajectory of this drive alone (1-based); 0 = every scan
};

const std::map<std::string, v1::ExportFormat>& ExportKinds() {
  static const std::map<std::string, v1::ExportFormat> kinds = {
      {"bt", v1::EXPORT_FORMAT_OCTOMAP_BT},
      {"ot", v1::EXPORT_FORMAT_OCTOMAP_OT},
      {"ply", v1::EXPORT_FORMAT_POINT_CLOUD_PLY},
      {"tum", v1::EXPORT_FORMAT_TRAJECTORY_TUM},
      {"kitti", v1::EXPORT_FORMAT_TRAJECTORY_KITTI}};
  return kinds;
}

// --format, else the extension of -o; -o defaults to the daemon's file name.
std::pair<v1::ExportFormat, std::string> ResolveFormat(const ExportFlags& f) {
  std::string name = f.format;
  if (name.empty() && !f.output.empty()) {
    name = fs::path(f.output).extension().string();
    if (!name.empty()) name = name.substr(1);
    if (name == "txt") name = "kitti";
  }
  const auto found = ExportKinds().find(name);
  if (found == ExportKinds().end()) {
    const std::string choices = " (use bt, ot, ply, tum or kitti)";
    if (!f.format.empty()) throw InputError("--format: unknown '" + f.format + "'" + choices);
    if (f.output.empty()) throw InputError("--format: needed when -o is not given" + choices);
    throw InputError("--format: not implied by -o '" + f.output + "'" + choices);
  }
  if (!f.output.empty()) return {found->second, f.output};
  // A drive of a format that has none (the daemon refuses it) keeps the map's name.
  return {
      found->second,
      rpc::ExportFileName(found->second, f.drive).value_or(*rpc::ExportFileName(found->second))};
}

// The job's poses for the preview, through a KITTI trajectory export:
// unlike GetResults it has no message-size limit however many scans.
std::vector<Transform> TrajectoryOf(rpc::MapBuilderClient& client, const std::string& job_id,
                                    const std::string& tmp_path) {
  struct RemoveOnExit {
    std::string path;
    ~RemoveOnExit() {
      std::error_code ignored;
      fs::remove(path, ignored);
    }
  } cleanup{tmp_path};
  client.ExportToFile(job_id, v1::EXPORT_FORMAT_TRAJECTORY_KITTI, tmp_path);
  return ReadKittiTrajectory(tmp_path);
}

int RunExport(const ExportFlags& f) {
  const auto [format, output] = ResolveFormat(f);
  UpDetectionOptions up_options;
  up_options.sensor_up = ParseSensorUp(f.sensor_up);
  Daemon daemon = ConnectToDaemon(f.remote);
  const v1::Job job = daemon.client->GetJob(f.job_id);
  if (job.state() != v1::JOB_STATE_SUCCEEDED) {
    throw std::runtime_error("job " + f.job_id + " is " + rpc::JobStateName(job.state()) +
                             "; only a succeeded job can be exported");
  }
  // Without --sensor-up, the job's sensor setting, else its scan format, says
  // where its sensors' up is.
  if (!up_options.sensor_up) {
    const int format = job.settings().scan_format();
    up_options.sensor_up = SensorUp(
        ParseSensorSetting(job.settings().config().sensor()),
        format == v1::SCAN_FORMAT_UNSPECIFIED ? CloudFormat::kAuto : rpc::FormatFromProto(format));
  }
  const fs::path parent = fs::path(output).parent_path();
  if (!parent.empty()) fs::create_directories(parent);
  uint64_t bytes = 0;
  WriteFileAtomically(output, [&](const std::string& tmp) {
    bytes = daemon.client->ExportToFile(f.job_id, format, tmp, f.drive);
  });
  std::fprintf(stderr, "wrote %s (%llu bytes)\n", output.c_str(),
               static_cast<unsigned long long>(bytes));
  const bool octomap =
      format == v1::EXPORT_FORMAT_OCTOMAP_BT || format == v1::EXPORT_FORMAT_OCTOMAP_OT;
  if (octomap && f.preview) {
    const std::string png = fs::path(output).replace_extension(".png").string();
    const UpDirection up = WriteMapPreview(
        output, TrajectoryOf(*daemon.client, f.job_id, png + ".poses.tmp"), png, {}, up_options);
    std::fprintf(stderr, "wrote %s (top-down preview; %s)\n", png.c_str(), up.reason.c_str());
  }
  return kOk;
}

}  // namespace

CommandRunner AddExportCommand(CLI::App& app) {
  auto flags = std::make_shared<ExportFlags>();
  app.add_option("JOB", flags->job_id, "Id of a succeeded job")->required();
  app.add_option("--format", flags->format,
                 "bt (OctoMap binary), ot (OctoMap full), ply (merged cloud), tum or kitti "
                 "(trajectory T_map_scan); default: from the extension of -o");
  app.add_option(
      "-o,--output", flags->output,
      "File to write (atomically: a staging file, then renamed); default: map.bt, map.ot, "
      "map.ply, trajectory.tum or trajectory.kitti");
  app.add_option("--sensor-up", flags->sensor_up, kSensorUpHelp);
  app.add_option("--drive", flags->drive,
                 "tum or kitti of a job of several drives: drive K's scans only (1-based; "
                 "default file trajectory-driveK.tum or .kitti); 0 = every scan")
      ->capture_default_str();
  app.add_flag("!--no-preview", flags->preview,
               "For bt/ot, skip the top-down preview PNG written next to FILE (FILE with .png)");
  AddRemoteOptions(app, flags->remote);
  return [flags] { return RunRemote("export", flags->remote, [&] { return RunExport(*flags); }); };
}

}  // namespace boicp::cli
