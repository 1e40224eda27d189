#include "local_pipeline.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "boicp/settings/map_batch_request.hpp"
#include "boicp/settings/setting_schema.hpp"
#include "boicp/settings/settings_json.hpp"
#include "boicp/util/atomic_file.hpp"
#include "cli_parsing.hpp"

namespace boicp::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string JoinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& name : names) joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

ScanFolderOptions FolderOptions(const MapSettings& s) {
  ScanFolderOptions options;
  options.layout = ParseScanLayout(s.layout);
  if (!s.intrinsics.empty()) options.intrinsics = ParseIntrinsics(s.intrinsics);
  options.tum_camera = s.camera;
  options.depth_scale = s.depth_scale;
  options.poses_as_priors = s.poses_as_priors;
  options.first = s.first;
  options.stride = s.stride;
  options.count = s.count;
  options.bag = s.bag;
  return options;
}

}  // namespace

json MapSettingsToJson(const MapSettings& s) {
  json out = settings::SettingsToJson(s, settings::kMap);
  out.update({{"path", s.path},
              {"more_paths", s.more_paths},
              {"layout", s.layout},
              {"pairing", s.pairing},
              {"pairs_file", s.pairs_file},
              {"overlap_threshold", s.overlap_threshold},
              {"extra_pairs_file", s.extra_pairs_file},
              {"first", s.first},
              {"stride", s.stride},
              {"count", s.count},
              {"intrinsics", s.intrinsics},
              {"camera", s.camera},
              {"depth_scale", s.depth_scale},
              {"poses_as_priors", s.poses_as_priors},
              {"topic", s.bag.topic},
              {"odometry_topic", s.bag.odometry_topic},
              {"start", s.bag.start},
              {"duration", s.bag.duration},
              {"min_interval", s.bag.min_interval}});
  return out;
}

MapSettings MapSettingsFromJson(const json& j, const std::string& source) {
  MapSettings s;
  settings::SettingsFromJson(j, settings::kMap, source, s);
  try {
    s.path = j.at("path").get<std::string>();
    // Runs of one drive written before several were read had none.
    s.more_paths = j.value("more_paths", std::vector<std::string>());
    s.layout = j.at("layout").get<std::string>();
    s.pairing = j.at("pairing").get<std::string>();
    s.pairs_file = j.at("pairs_file").get<std::string>();
    // Runs written before these settings existed had neither.
    s.overlap_threshold = j.value("overlap_threshold", 0.0);
    s.extra_pairs_file = j.value("extra_pairs_file", std::string());
    s.first = j.at("first").get<int>();
    s.stride = j.at("stride").get<int>();
    s.count = j.at("count").get<int>();
    s.intrinsics = j.at("intrinsics").get<std::string>();
    s.camera = j.at("camera").get<std::string>();
    s.depth_scale = j.at("depth_scale").get<double>();
    s.poses_as_priors = j.at("poses_as_priors").get<bool>();
    // Runs written before bags were read had none of these.
    s.bag.topic = j.value("topic", std::string());
    s.bag.odometry_topic = j.value("odometry_topic", std::string());
    s.bag.start = j.value("start", 0.0);
    s.bag.duration = j.value("duration", 0.0);
    s.bag.min_interval = j.value("min_interval", 0.0);
    return s;
  } catch (const json::exception& e) {
    throw InputError(source + ": bad run settings (" + e.what() + ")");
  }
}

std::vector<PairIndex> ReadPairsFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the pairs file");
  std::vector<PairIndex> pairs;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (line.compare(first, 6, "source") == 0) continue;  // a "source,target" header
    int source = -1, target = -1;
    char end = 0;
    if (std::sscanf(line.c_str(), " %d , %d %c", &source, &target, &end) != 2 &&
        std::sscanf(line.c_str(), " %d %d %c", &source, &target, &end) != 2) {
      throw InputError(path + ":" + std::to_string(number) + ": expected 'source,target' indices");
    }
    pairs.push_back({source, target});
  }
  if (pairs.empty()) throw InputError(path + ": lists no pairs");
  return pairs;
}

namespace {

// The pairing the settings ask for, with the pairs read from their files.
PairingRequest PairingOfSettings(const MapSettings& settings) {
  PairingRequest pairing;
  const std::optional<PairingMode> mode = PairingModeFromName(settings.pairing);
  if (!mode) {
    throw InputError("--pairing: '" + settings.pairing +
                     "' is not consecutive, overlap or explicit");
  }
  pairing.mode = *mode;
  if (pairing.mode == PairingMode::kExplicit) {
    if (settings.pairs_file.empty()) throw InputError("--pairing explicit needs a pairs FILE");
    if (!settings.extra_pairs_file.empty()) {
      throw InputError("--extra-pairs: explicit pairing lists every pair in its FILE");
    }
    pairing.pairs = ReadPairsFile(settings.pairs_file);
  } else if (!settings.extra_pairs_file.empty()) {
    pairing.pairs = ReadPairsFile(settings.extra_pairs_file);
  }
  if (settings.overlap_threshold != 0.0 && pairing.mode != PairingMode::kOverlap) {
    throw InputError("--overlap-threshold: only overlap pairing has one");
  }
  pairing.overlap_threshold = settings.overlap_threshold;
  return pairing;
}

// The run of the scans of `folders` (each a drive, read from `wheres`)
// with `settings`.
LocalRun RunOfScans(const MapSettings& settings, std::vector<ScanFolder> folders,
                    const std::vector<std::string>& wheres) {
  LocalRun run;
  run.settings = settings;
  std::vector<ScanSource> scans;
  PairingRequest pairing = PairingOfSettings(settings);
  for (size_t d = 0; d < folders.size(); ++d) {
    ScanFolder& folder = folders[d];
    const int n = static_cast<int>(folder.scans.size());
    if (n < 2) {
      throw InputError(wheres[d] + ": a " + (folders.size() > 1 ? "drive" : "map") +
                       " needs at least 2 scans, the selection has " + std::to_string(n));
    }
    if (d > 0) pairing.drive_starts.push_back(static_cast<int>(scans.size()));
    run.drive_paths.push_back(wheres[d]);
    run.description += (d > 0 ? "; " : "") +
                       (folders.size() > 1 ? wheres[d] + ": " : std::string()) + folder.description;
    for (ScanSource& scan : folder.scans) scans.push_back(std::move(scan));
  }
  run.layout = folders.front().layout;
  // Parallelism is across pairs; inside one registration it is one thread,
  // as the daemon's default --registration-threads.
  run.batch = boicp::settings::MakeMapBatch(
      std::move(scans), settings, std::move(pairing), 1,
      settings.pairing == "explicit" ? settings.pairs_file : settings.extra_pairs_file);
  return run;
}

}  // namespace

LocalRun PrepareRun(const MapSettings& settings) {
  std::vector<std::string> paths = {settings.path};
  paths.insert(paths.end(), settings.more_paths.begin(), settings.more_paths.end());
  std::vector<ScanFolder> folders;
  for (const std::string& path : paths) {
    folders.push_back(ReadScanFolder(path, FolderOptions(settings)));
  }
  return RunOfScans(settings, std::move(folders), paths);
}

LocalRun PrepareRun(const MapSettings& settings, const std::vector<std::string>& files) {
  std::vector<ScanFolder> folders;
  folders.push_back(ReadScanList(files, FolderOptions(settings)));
  return RunOfScans(settings, std::move(folders), {"the list of scans"});
}

MapSettings WithAbsolutePaths(MapSettings settings) {
  const auto absolute = [](std::string& path) {
    if (!path.empty()) path = fs::absolute(path).lexically_normal().string();
  };
  absolute(settings.path);
  for (std::string& path : settings.more_paths) absolute(path);
  absolute(settings.pairs_file);
  absolute(settings.extra_pairs_file);
  return settings;
}

void ChooseMapRunSettings(LocalRun& run, int threads, uint64_t max_fusion_mb) {
  MapBatch& batch = run.batch;
  const std::vector<RangeProfile> profiles = ProfileScans(batch.scans, threads);
  run.chosen = ChooseBatchSettings(batch, profiles);
  RequireVoxelsFitExtent(batch.config, ProfilesExtent(profiles));
  batch.map.max_fusion_bytes = static_cast<size_t>(max_fusion_mb << 20);
  RequireFusionWithinLimit(batch.scans, profiles, batch.map.occupancy, batch.map.max_fusion_bytes);
  batch.map.fusion_threads = threads;
}

void PrintRunSettings(const LocalRun& run) {
  const BoIcpConfig& config = run.batch.config;
  const OccupancySettings& occupancy = run.batch.map.occupancy;
  std::fprintf(
      stderr,
      "settings: voxel %.3g m, refine voxel %.3g m, translation bounds %.3g,%.3g,%.3g m, "
      "rotation bounds %.3g,%.3g,%.3g rad, map resolution %.3g m, ray length %.3g m%s%s\n",
      config.voxel, config.EffectiveRefineVoxel(), config.translation_bounds[0],
      config.translation_bounds[1], config.translation_bounds[2], config.rotation_bounds[0],
      config.rotation_bounds[1], config.rotation_bounds[2], occupancy.resolution,
      occupancy.max_range,
      run.chosen.fields.empty() ? "" : "; from the scans: ", JoinNames(run.chosen.fields).c_str());
  if (!run.chosen.measured.empty()) {
    std::fprintf(stderr, "settings: sensor %s (%s)\n", SensorKindName(run.chosen.sensor).c_str(),
                 run.chosen.sensor_reason.c_str());
  }
  size_t far_returns = 0, scans_with_far_returns = 0;
  for (const MeasuredScan& m : run.chosen.measured) {
    far_returns += m.far_returns;
    scans_with_far_returns += m.far_returns > 0;
  }
  if (far_returns > 0) {
    std::fprintf(stderr,
                 "settings: %zu points of %zu of the %zu measured scans set aside as far returns "
                 "(they stay in the scans; run.json lists them)\n",
                 far_returns, scans_with_far_returns, run.chosen.measured.size());
  }
  if (const std::string rescaled = DescribeScansAtAnotherScale(run.batch.scale);
      !rescaled.empty()) {
    std::fprintf(stderr, "settings: %s\n", rescaled.c_str());
  }
}

json RunManifestJson(const LocalRun& run) {
  json manifest = MapSettingsToJson(run.settings);
  manifest["chosen"] = settings::ConfigToJson(run.batch.config);
  manifest["chosen"]["map_resolution"] = run.batch.map.occupancy.resolution;
  manifest["chosen"]["map_max_range"] = run.batch.map.occupancy.max_range;
  manifest["auto"] = run.chosen.fields;
  manifest["far_returns"] = json::array();
  for (const MeasuredScan& m : run.chosen.measured) {
    manifest["far_returns"].push_back(
        {{"scan", run.batch.scans[m.scan].path}, {"points", m.far_returns}});
  }
  if (!run.chosen.measured.empty()) {
    manifest["sensor"] = {{"type", SensorKindName(run.chosen.sensor)},
                          {"why", run.chosen.sensor_reason}};
  }
  return manifest;
}

std::vector<PairIndex> FixedPlanPairs(const PairingPlan& plan) {
  std::vector<PairIndex> pairs = plan.chain;
  pairs.insert(pairs.end(), plan.extras.begin(), plan.extras.end());
  return pairs;
}

std::map<PairIndex, PairResult> ReadStoredPairs(const LocalRun& run,
                                                const std::vector<PairIndex>& pairs,
                                                const std::vector<std::string>& dirs) {
  std::map<PairIndex, PairResult> results;
  std::string missing;
  int missing_count = 0;
  for (const PairIndex& pair : pairs) {
    for (const std::string& dir : dirs) {
      std::optional<PairFile> file = ReadPairFile(dir, pair);
      if (!file) continue;
      if (file->settings != PairSettings(run.batch.scans, pair, run.batch.config)) {
        throw InputError(PairFilePath(dir, pair) + ": computed with other settings than " +
                         RunManifestPath(dir) + " (rerun that shard)");
      }
      results[pair] = std::move(file->result);
      break;
    }
    if (results.count(pair) == 0 && ++missing_count <= 10) {
      missing += (missing.empty() ? "" : ", ") + PairName(pair);
    }
  }
  if (missing_count > 0) {
    throw InputError(std::to_string(missing_count) + " of " + std::to_string(pairs.size()) +
                     " pair results missing (" + missing + (missing_count > 10 ? ", ..." : "") +
                     "); run or rerun the shards that own them");
  }
  return results;
}

std::string RunManifestPath(const std::string& out_dir) {
  return (fs::path(out_dir) / "run.json").string();
}

void WriteRunManifest(const LocalRun& run, const std::string& out_dir) {
  fs::create_directories(out_dir);
  WriteTextFileAtomically(RunManifestPath(out_dir), RunManifestJson(run).dump(1) + "\n");
}

MapSettings ReadRunManifest(const std::string& dir) {
  const std::string path = RunManifestPath(dir);
  std::ifstream in(path);
  if (!in) throw InputError(path + ": no such file (not the output folder of boicp map)");
  json manifest;
  try {
    manifest = json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(path + ": not JSON (" + e.what() + ")");
  }
  return MapSettingsFromJson(manifest, path);
}

std::string ManifestDifferences(const MapSettings& a, const MapSettings& b) {
  const json ja = MapSettingsToJson(a), jb = MapSettingsToJson(b);
  std::string differences;
  for (const auto& [key, value] : ja.items()) {
    if (jb.contains(key) && jb[key] == value) continue;
    differences += (differences.empty() ? "" : ", ") + key + ": " + value.dump() + " vs " +
                   (jb.contains(key) ? jb[key].dump() : std::string("(none)"));
  }
  return differences;
}

}  // namespace boicp::cli
