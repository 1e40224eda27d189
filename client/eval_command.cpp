// `boicp eval OUTDIR --reference REF`: how far a map written by `boicp map`
// is from a reference, so that accuracy is measured the same way on every
// drive. REF is a scan folder with its own poses (KITTI poses.txt and
// calib.txt, TUM groundtruth.txt, 7-Scenes pose files), a KITTI trajectory
// file with one pose per scan of the map, or a revisits CSV (earlier, later,
// ..., tx_m, ty_m, tz_m, yaw_deg, verdict) like the VLP-16 drive's.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "boicp/io/scan_folder.hpp"
#include "boicp/io/trajectory_io.hpp"
#include "boicp/mapping/trajectory_error.hpp"
#include "boicp/util/text.hpp"
#include "boicp/util/types.hpp"
#include "commands.hpp"
#include "run_command.hpp"

namespace boicp::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct EvalFlags {
  std::string out_dir;
  std::string reference;
  double max_rotation_deg = 2.0;
  double max_translation = 0.0;  // 0: 3 x the run's inlier distance
  double segment = 0.0;
  bool json = false;
};

json ReadJsonFile(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": missing; is this a folder `boicp map` wrote?");
  try {
    return json::parse(in);
  } catch (const std::exception& e) {
    throw InputError(path.string() + ": not JSON (" + e.what() + ")");
  }
}

// The map: its poses, its pairs, and each scan's file as pairs.json names it.
struct WrittenMap {
  std::vector<Transform> poses;
  json pairs;
  std::vector<std::string> scan_paths;
  double inlier_distance = 0.0;  // metres, from run.json; 0 when unknown
};

WrittenMap ReadWrittenMap(const std::string& out_dir) {
  const fs::path dir(out_dir);
  WrittenMap map;
  if (!fs::is_regular_file(dir / "trajectory.kitti")) {
    throw InputError((dir / "trajectory.kitti").string() +
                     ": missing; is this a folder `boicp map` wrote?");
  }
  map.poses = ReadKittiTrajectory((dir / "trajectory.kitti").string());
  map.pairs = ReadJsonFile(dir / "pairs.json");
  map.scan_paths.assign(map.poses.size(), "");
  for (const json& pair : map.pairs) {
    for (const char* end : {"source", "target"}) {
      const int index = pair.at(end).get<int>();
      if (index < 0 || static_cast<size_t>(index) >= map.poses.size()) {
        throw InputError("pairs.json names scan " + std::to_string(index) + " of " +
                         std::to_string(map.poses.size()));
      }
      map.scan_paths[static_cast<size_t>(index)] =
          pair.at(std::string(end) + "_path").get<std::string>();
    }
  }
  if (fs::is_regular_file(dir / "run.json")) {
    const json run = ReadJsonFile(dir / "run.json");
    if (run.contains("chosen") && run["chosen"].contains("refine_voxel")) {
      map.inlier_distance = 1.5 * run["chosen"]["refine_voxel"].get<double>();
    }
  }
  return map;
}

std::string Stem(const std::string& path) { return fs::path(path).stem().string(); }

// The reference pose of each scan of the map, where the reference has one.
std::vector<std::optional<Transform>> ReferencePoses(const WrittenMap& map,
                                                     const std::string& reference) {
  std::vector<std::optional<Transform>> poses(map.poses.size());
  if (fs::is_regular_file(reference)) {
    const std::vector<Transform> listed = ReadKittiTrajectory(reference);
    if (listed.size() != map.poses.size()) {
      throw InputError(reference + ": " + std::to_string(listed.size()) + " poses for a map of " +
                       std::to_string(map.poses.size()) + " scans");
    }
    for (size_t i = 0; i < listed.size(); ++i) poses[i] = listed[i];
    return poses;
  }
  const ScanFolder folder = ReadScanFolder(reference);
  std::map<std::string, std::optional<Transform>> by_file;
  for (size_t i = 0; i < folder.scans.size(); ++i) {
    const std::optional<Transform>& pose = folder.reference_poses.at(i);
    by_file[fs::weakly_canonical(folder.scans[i].path).string()] = pose;
  }
  for (size_t i = 0; i < map.scan_paths.size(); ++i) {
    if (map.scan_paths[i].empty()) continue;
    const auto found = by_file.find(fs::weakly_canonical(map.scan_paths[i]).string());
    if (found != by_file.end()) poses[i] = found->second;
  }
  return poses;
}

// Each pair's error against the reference, and per kind: count, wrong, and
// wrong among the trusted.
json PairErrors(const WrittenMap& map, const std::vector<std::optional<Transform>>& reference,
                double max_rotation_deg, double max_translation) {
  json listed = json::array();
  std::map<std::string, json> kinds;
  for (const json& pair : map.pairs) {
    const auto s = pair.at("source").get<size_t>(), t = pair.at("target").get<size_t>();
    if (!reference[s] || !reference[t]) continue;
    Transform estimated = Transform::Identity();
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) estimated(r, c) = pair.at("transform")[r][c].get<double>();
    }
    const Transform truth = reference[t]->inverse() * *reference[s];
    const Transform error = truth.inverse() * estimated;
    const double rotation = RotationAngle(error) * 180.0 / M_PI;
    const double translation = TranslationNorm(error);
    const bool wrong = rotation > max_rotation_deg || translation > max_translation;
    const bool doubtful = pair.value("doubtful", false);
    const std::string kind = pair.value("kind", "chain");
    listed.push_back({{"source", s},
                      {"target", t},
                      {"kind", kind},
                      {"in_graph", pair.value("in_graph", true)},
                      {"doubtful", doubtful},
                      {"rotation_error_deg", rotation},
                      {"translation_error_m", translation},
                      {"wrong", wrong}});
    json& summary = kinds[kind];
    if (summary.is_null())
      summary = {{"pairs", 0},
                 {"wrong_trusted", 0},
                 {"wrong_doubtful", 0},
                 {"right_doubtful", 0},
                 {"wrong_in_graph", 0}};
    summary["pairs"] = summary["pairs"].get<int>() + 1;
    const char* cell = wrong ? (doubtful ? "wrong_doubtful" : "wrong_trusted")
                             : (doubtful ? "right_doubtful" : nullptr);
    if (cell != nullptr) summary[cell] = summary[cell].get<int>() + 1;
    if (wrong && pair.value("in_graph", true)) {
      summary["wrong_in_graph"] = summary["wrong_in_graph"].get<int>() + 1;
    }
  }
  return {{"pairs", listed}, {"by_kind", kinds}};
}

// The map against each row of a revisits CSV whose verdict is "revisit".
json RevisitErrors(const WrittenMap& map, const std::string& csv_path) {
  std::ifstream in(csv_path);
  if (!in) throw InputError(csv_path + ": cannot be read");
  std::map<std::string, size_t> scan_of;
  for (size_t i = 0; i < map.scan_paths.size(); ++i) scan_of[Stem(map.scan_paths[i])] = i;
  json rows = json::array();
  std::string line;
  std::getline(in, line);  // header
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (Trim(line).empty()) continue;
    std::vector<std::string> cells;
    std::stringstream split(line);
    for (std::string cell; std::getline(split, cell, ',');) cells.push_back(Trim(cell));
    if (cells.size() < 9) {
      throw InputError(csv_path + ":" + std::to_string(line_number) +
                       ": expected earlier,later,inlier_share,rms,tx,ty,tz,yaw_deg,verdict");
    }
    if (cells[8] != "revisit") continue;
    const auto earlier = scan_of.find(Stem(cells[0])), later = scan_of.find(Stem(cells[1]));
    if (earlier == scan_of.end() || later == scan_of.end()) continue;
    double tx = 0, ty = 0, tz = 0, yaw = 0;
    try {
      tx = std::stod(cells[4]), ty = std::stod(cells[5]), tz = std::stod(cells[6]);
      yaw = std::stod(cells[7]);
    } catch (const std::exception&) {
      throw InputError(csv_path + ":" + std::to_string(line_number) + ": not a number");
    }
    // The revisit maps the later scan into the earlier one's frame.
    const Transform mapped = map.poses[earlier->second].inverse() * map.poses[later->second];
    const double yaw_mapped = std::atan2(mapped(1, 0), mapped(0, 0)) * 180.0 / M_PI;
    double yaw_error = std::fmod(std::abs(yaw_mapped - yaw), 360.0);
    yaw_error = std::min(yaw_error, 360.0 - yaw_error);
    const double translation = (mapped.topRightCorner<3, 1>() - Eigen::Vector3d(tx, ty, tz)).norm();
    rows.push_back({{"earlier", cells[0]},
                    {"later", cells[1]},
                    {"translation_error_m", translation},
                    {"yaw_error_deg", yaw_error}});
  }
  return rows;
}

void PrintEvaluation(const json& result) {
  if (result.contains("trajectory")) {
    const json& t = result["trajectory"];
    std::printf("ATE %.4f m RMS, %.4f m max over %d scans (rigid alignment, no scale)\n",
                t["ate_rmse_m"].get<double>(), t["ate_max_m"].get<double>(), t["scans"].get<int>());
    if (t["segments"].get<int>() > 0) {
      std::printf("drift %.4f m per metre over %.2f m stretches (%d)\n",
                  t["drift_per_metre"].get<double>(), t["segment_m"].get<double>(),
                  t["segments"].get<int>());
    }
    std::printf("pairs wrong beyond %.2f deg or %.4f m:\n",
                result["max_rotation_deg"].get<double>(),
                result["max_translation_m"].get<double>());
    for (const auto& [kind, s] : result["pair_errors"]["by_kind"].items()) {
      std::printf(
          "  %-6s %4d pairs: %d wrong and trusted, %d wrong and doubtful, %d right but "
          "doubtful, %d wrong in the graph\n",
          kind.c_str(), s["pairs"].get<int>(), s["wrong_trusted"].get<int>(),
          s["wrong_doubtful"].get<int>(), s["right_doubtful"].get<int>(),
          s["wrong_in_graph"].get<int>());
    }
  }
  if (result.contains("revisits")) {
    int agree = 0;
    double worst_t = 0.0, worst_yaw = 0.0;
    for (const json& row : result["revisits"]) {
      const double t = row["translation_error_m"].get<double>();
      const double yaw = row["yaw_error_deg"].get<double>();
      agree += t <= 0.3 && yaw <= 2.0;
      worst_t = std::max(worst_t, t);
      worst_yaw = std::max(worst_yaw, yaw);
    }
    std::printf("revisits: %d of %zu within 0.3 m and 2 deg; worst %.3f m, %.2f deg\n", agree,
                result["revisits"].size(), worst_t, worst_yaw);
  }
}

int RunEval(const EvalFlags& flags) {
  const WrittenMap map = ReadWrittenMap(flags.out_dir);
  json result;
  if (fs::path(flags.reference).extension() == ".csv") {
    result["revisits"] = RevisitErrors(map, flags.reference);
  } else {
    const std::vector<std::optional<Transform>> reference = ReferencePoses(map, flags.reference);
    const TrajectoryError error = CompareTrajectories(map.poses, reference, flags.segment);
    const double max_translation =
        flags.max_translation > 0.0 ? flags.max_translation : 3.0 * map.inlier_distance;
    if (!(max_translation > 0.0)) {
      throw InputError("--max-translation: " + flags.out_dir +
                       "/run.json gives no refine_voxel to choose it from; set it");
    }
    result["trajectory"] = {
        {"scans", error.scans},       {"ate_rmse_m", error.ate_rmse},
        {"ate_max_m", error.ate_max}, {"segment_m", error.segment},
        {"segments", error.segments}, {"drift_per_metre", error.drift_per_metre}};
    result["max_rotation_deg"] = flags.max_rotation_deg;
    result["max_translation_m"] = max_translation;
    result["pair_errors"] = PairErrors(map, reference, flags.max_rotation_deg, max_translation);
  }
  if (flags.json) {
    std::cout << result.dump() << std::endl;
  } else {
    PrintEvaluation(result);
  }
  return kOk;
}

}  // namespace

CommandRunner AddEvalCommand(CLI::App& app) {
  auto flags = std::make_shared<EvalFlags>();
  app.add_option("OUTDIR", flags->out_dir, "A folder `boicp map` wrote")->required();
  app.add_option("--reference", flags->reference,
                 "The scan folder with its own poses (KITTI poses.txt + calib.txt, TUM "
                 "groundtruth.txt, 7-Scenes pose files), a KITTI trajectory file with one pose "
                 "per scan, or a revisits CSV (earlier,later,...,tx_m,ty_m,tz_m,yaw_deg,verdict)")
      ->required();
  app.add_option("--max-rotation-deg", flags->max_rotation_deg,
                 "A pair is wrong beyond this rotation error (degrees)")
      ->capture_default_str();
  app.add_option("--max-translation", flags->max_translation,
                 "A pair is wrong beyond this translation error (metres); default 3 x the "
                 "run's inlier distance");
  app.add_option("--segment", flags->segment,
                 "Metres of reference path the drift is measured over; default a tenth of it");
  app.add_flag("--json", flags->json,
               "One JSON object on stdout: trajectory {scans, ate_rmse_m, ate_max_m, segment_m, "
               "segments, drift_per_metre}, pair_errors {pairs [...], by_kind}, or revisits [...]");
  return [flags] { return RunCommand("eval", [&] { return RunEval(*flags); }); };
}

}  // namespace boicp::cli
