// boicp-demo-client: the daemon demo. Uploads a generated drive (or the
// scans of a folder), submits one batch with consecutive pairing, shows its
// progress and writes the map and trajectory files.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "boicp/evaluation.hpp"
#include "boicp/trajectory_io.hpp"
#include "demo_sequence.hpp"
#include "map_builder_client.hpp"

namespace {

namespace fs = std::filesystem;
namespace v1 = ::boicp::v1;
using boicp::client::MapBuilderClient;

struct Flags {
  std::string server = "127.0.0.1:50051";
  std::string data, out = "demo-out", token_file, tls_ca;
  std::string preset = "C", pairing = "consecutive";
  int scans = 0;  // 0: 8 generated scans, or every scan of --data
  uint64_t seed = 7;
  double resolution = 0.2, max_range = 40.0;
  std::vector<double> rotation_bounds = {0.2, 0.2, 3.14159};
};

// The scan files of a folder (or of its velodyne/ subfolder, KITTI's layout), sorted.
std::vector<fs::path> ScanFiles(const std::string& folder, int limit) {
  fs::path dir = folder;
  if (fs::is_directory(dir / "velodyne")) dir /= "velodyne";
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".bin" || ext == ".pcd" || ext == ".ply" || ext == ".xyz") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  if (limit > 0 && static_cast<int>(files.size()) > limit) files.resize(static_cast<size_t>(limit));
  if (files.size() < 2) throw std::runtime_error(dir.string() + ": needs at least 2 scan files");
  return files;
}

v1::ScanFormat FormatOf(const fs::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".bin") return v1::SCAN_FORMAT_KITTI_BIN;
  if (ext == ".pcd") return v1::SCAN_FORMAT_PCD;
  if (ext == ".ply") return v1::SCAN_FORMAT_PLY;
  return v1::SCAN_FORMAT_XYZ;
}

std::string ReadToken(const std::string& path) {
  if (path.empty()) return "";
  std::ifstream in(path);
  std::string token;
  in >> token;
  if (token.empty()) throw std::runtime_error(path + ": no token");
  return token;
}

// Prints finished pairs, and the progress line when the stage or its count moves.
void PrintEvent(const v1::JobEvent& event, std::string& last_line) {
  const v1::Job& job = event.job();
  if (event.has_pair()) {
    const v1::PairResult& p = event.pair();
    std::printf("  pair %u->%u  %.1f s  fitness %.3f  confidence %.3f\n", p.source(), p.target(),
                p.runtime_s(), p.fitness(), p.confidence());
  }
  std::string line = "[" + job.stage() + "]";
  if (job.stage_total() > 0) {
    line += " " + std::to_string(job.stage_done()) + "/" + std::to_string(job.stage_total());
  }
  if (line == last_line) return;
  last_line = line;
  const std::string eta = job.eta_seconds() >= 0
                              ? ", ETA " + std::to_string(std::lround(job.eta_seconds())) + " s"
                              : "";
  std::printf("%s%s\n", line.c_str(), eta.c_str());
  std::fflush(stdout);
}

int Run(const Flags& f) {
  boicp::client::ConnectOptions connect;
  connect.address = f.server;
  connect.token = ReadToken(f.token_file);
  connect.tls_ca_file = f.tls_ca;
  MapBuilderClient client(boicp::client::Connect(connect), connect.token);
  fs::create_directories(f.out);

  v1::SubmitBatchRequest request;
  std::vector<boicp::Transform> truth;
  const auto upload_start = std::chrono::steady_clock::now();
  if (f.data.empty()) {
    const int count = f.scans > 0 ? f.scans : 8;
    std::printf("generating a drive of %d scans along the synthetic street\n", count);
    for (const auto& scan : boicp::client::MakeDemoSequence(count, f.seed)) {
      v1::ScanMetadata metadata;
      metadata.set_format(v1::SCAN_FORMAT_KITTI_BIN);
      request.add_scan_ids(client.Upload(scan.kitti_bytes, metadata).scan_id());
      truth.push_back(scan.T_world_scan);
    }
  } else {
    for (const fs::path& file : ScanFiles(f.data, f.scans)) {
      v1::ScanMetadata metadata;
      metadata.set_format(FormatOf(file));
      request.add_scan_ids(client.UploadFile(file.string(), metadata).scan_id());
    }
  }
  const double upload_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - upload_start).count();
  std::printf("uploaded %d scans in %.1f s\n", request.scan_ids_size(), upload_s);

  request.mutable_pairing()->set_mode(f.pairing == "keyframes"
                                          ? v1::PairingPolicy::MODE_KEYFRAMES
                                          : v1::PairingPolicy::MODE_CONSECUTIVE);
  v1::RegistrationConfig& config = *request.mutable_config();
  config.set_preset(f.preset);
  config.mutable_rotation_bounds()->set_x(f.rotation_bounds.at(0));
  config.mutable_rotation_bounds()->set_y(f.rotation_bounds.at(1));
  config.mutable_rotation_bounds()->set_z(f.rotation_bounds.at(2));
  config.set_seed(f.seed);
  request.mutable_map()->set_resolution(f.resolution);
  request.mutable_map()->set_max_range(f.max_range);
  request.set_label(f.data.empty() ? "demo: synthetic drive" : "demo: " + f.data);

  const auto start = std::chrono::steady_clock::now();
  const v1::Job queued = client.Submit(request);
  std::printf("submitted %s: %u scans, %u pairs, preset %s\n", queued.job_id().c_str(),
              queued.num_scans(), queued.pairs_total(), f.preset.c_str());
  std::string last_line;
  const v1::Job done = client.Watch(
      queued.job_id(), [&last_line](const v1::JobEvent& event) { PrintEvent(event, last_line); });
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (done.state() != v1::JOB_STATE_SUCCEEDED) {
    std::fprintf(stderr, "job %s ended %s: %s\n", done.job_id().c_str(), done.stage().c_str(),
                 done.error().c_str());
    return 1;
  }
  const std::vector<std::pair<v1::ExportFormat, std::string>> exports = {
      {v1::EXPORT_FORMAT_OCTOMAP_BT, "map.bt"},
      {v1::EXPORT_FORMAT_OCTOMAP_OT, "map.ot"},
      {v1::EXPORT_FORMAT_TRAJECTORY_TUM, "trajectory.tum"},
      {v1::EXPORT_FORMAT_TRAJECTORY_KITTI, "trajectory.kitti"},
      {v1::EXPORT_FORMAT_POINT_CLOUD_PLY, "map.ply"}};
  for (const auto& [format, name] : exports) {
    const std::string path = (fs::path(f.out) / name).string();
    const uint64_t bytes = client.ExportToFile(done.job_id(), format, path);
    std::printf("wrote %s (%llu bytes)\n", path.c_str(), static_cast<unsigned long long>(bytes));
  }
  std::printf("batch %s: %u pairs in %.1f s (%.1f pairs/min)\n", done.job_id().c_str(),
              done.pairs_done(), wall, 60.0 * done.pairs_done() / std::max(wall, 1e-9));

  if (!truth.empty()) {
    // Relative motion between consecutive scans, estimated vs generated.
    const auto poses = boicp::ReadKittiTrajectory((fs::path(f.out) / "trajectory.kitti").string());
    double worst_deg = 0.0, worst_m = 0.0;
    for (size_t i = 0; i + 1 < poses.size(); ++i) {
      const boicp::Transform estimate = poses[i + 1].inverse() * poses[i];
      const boicp::Transform reference = truth[i + 1].inverse() * truth[i];
      worst_deg = std::max(worst_deg, boicp::RotationErrorDeg(estimate, reference));
      worst_m = std::max(worst_m, boicp::TranslationErrorM(estimate, reference));
    }
    std::printf("against the generated truth: worst pair error %.3f deg, %.3f m\n", worst_deg,
                worst_m);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"boicp-demo-client: submit a demo batch to boicpd and write its map"};
  Flags f;
  app.add_option("--server", f.server, "boicpd address HOST:PORT")->capture_default_str();
  app.add_option("--data", f.data, "Folder of scans (.bin/.pcd/.ply/.xyz); default: generated");
  app.add_option("--scans", f.scans,
                 "Generated scans (default 8), or the most taken from --data (default all)")
      ->capture_default_str();
  app.add_option("--out", f.out, "Folder for map.bt, map.ot, trajectories and map.ply")
      ->capture_default_str();
  app.add_option("--preset", f.preset, "BO-ICP preset A, B or C")->capture_default_str();
  app.add_option("--pairing", f.pairing, "consecutive or keyframes")->capture_default_str();
  app.add_option("--seed", f.seed, "Job seed (and the generated drive's)")->capture_default_str();
  app.add_option("--rotation-bounds", f.rotation_bounds, "roll,pitch,yaw half-widths (rad)")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--resolution", f.resolution, "OctoMap resolution (m)")->capture_default_str();
  app.add_option("--max-range", f.max_range, "OctoMap ray length (m)")->capture_default_str();
  app.add_option("--auth-token-file", f.token_file, "Bearer token file");
  app.add_option("--tls-ca", f.tls_ca, "PEM roots for a TLS daemon");
  CLI11_PARSE(app, argc, argv);
  try {
    return Run(f);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "boicp-demo-client: error: %s\n", e.what());
    return 1;
  }
}
