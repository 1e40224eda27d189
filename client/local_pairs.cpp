#include "local_pairs.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "boicp/settings/pair_result_json.hpp"
#include "boicp/settings/settings_json.hpp"
#include "boicp/util/atomic_file.hpp"
#include "json_output.hpp"

namespace boicp::cli {
namespace {

using nlohmann::json;

json ScanSettings(const ScanSource& scan) {
  json out = {{"path", scan.path}, {"format", CloudFormatName(scan.load.format)}};
  if (scan.load.format == CloudFormat::kDepthPng) {
    const DepthOptions& d = scan.load.depth;
    if (d.intrinsics) {
      out["intrinsics"] = {d.intrinsics->fx, d.intrinsics->fy, d.intrinsics->cx, d.intrinsics->cy};
    }
    out["depth_scale"] = d.depth_scale;
    out["invalid_values"] = d.invalid_values;
  }
  if (const std::optional<BagMessageRef>& m = scan.load.bag_message) {
    out["bag_message"] = {m->log_time_ns, m->position, m->offset, m->size};
    if (m->file > 0) out["bag_message"].push_back(m->file);  // a split bag's later files
  }
  out["prior_pose"] = scan.prior_pose ? TransformToJson(*scan.prior_pose) : json(nullptr);
  return out;
}

// The config object of a pair's settings: the registration settings as used,
// without the thread count, which no result depends on.
json PairConfigJson(const BoIcpConfig& config) {
  json out = settings::ConfigToJson(config);
  out.erase("threads");
  return out;
}

// Pair files written before the config object followed the schema named a
// few settings otherwise and listed engine constants no front end sets. Such
// a config is read under the old names and written as PairSettings writes it
// now, so that those pairs are reused rather than registered again.
void UpgradeOldPairConfig(json& config, const std::string& source) {
  // Pairs registered before the budget existed ran the paper's full search,
  // which the fixed budget still runs; an auto run registers them again.
  if (!config.contains("budget")) config["budget"] = BudgetName(Budget::kFixed);
  // Before the sensor could be set, the format and the geometry chose it, as
  // "auto" still does.
  if (!config.contains("sensor")) config["sensor"] = SensorSettingName(std::nullopt);
  // Before methods could be chosen, every pair ran BO-ICP.
  if (!config.contains("method")) config["method"] = kDefaultMethod;
  if (!config.contains("retry_when_doubtful")) return;
  static const std::pair<const char*, const char*> kRenamed[] = {
      {"max_correspondence_distance", "max_correspondence"},
      {"icp_max_iterations", "icp_iterations"},
      {"max_range", "scan_max_range"}};
  for (const auto& [old_key, key] : kRenamed) {
    if (config.contains(old_key)) config[key] = config.at(old_key);
  }
  config["no_retry"] = !config.at("retry_when_doubtful").get<bool>();
  // Their searches ran point-to-point ICP, the only one there was.
  if (!config.contains("icp_objective")) config["icp_objective"] = "point";
  config = PairConfigJson(settings::ConfigFromJson(config, source));
}

// Pair files without a "format" (written before there was one) lack the
// keys added since: they read as trusted (no doubtful flag, PairResult's
// confidence), unknown (overlap, search_reach), the full search
// (answered_by, as every pair was before the ladder) and the settings under
// today's names. Files of format 1 predate the unconstrained slides:
// not measured (null). Files of a later format are refused, not misread.
void MigratePairFile(json& j, const std::string& path) {
  const int format = j.value("format", 0);
  if (format > kPairFileFormat) {
    throw NewerPairFileError(path + ": format " + std::to_string(format) +
                             " is newer than this boicp reads (" + std::to_string(kPairFileFormat) +
                             "); use the boicp that wrote it");
  }
  if (format == kPairFileFormat) return;
  if (format == 0) {
    if (!j.contains("doubtful")) {
      j["doubtful"] = false;
      j["confidence"] = 1.0;
    }
    for (const char* key : {"overlap", "search_reach"}) {
      if (!j.contains(key)) j[key] = nullptr;
    }
    if (!j.contains("answered_by")) j["answered_by"] = RungName(Rung::kFullSearch);
    UpgradeOldPairConfig(j.at("settings").at("config"), path);
  }
  if (!j.contains("unconstrained")) j["unconstrained"] = nullptr;
  j["format"] = kPairFileFormat;
}

// `result` in `format`, with the paths of its two scans (pair files and
// pairs.json name them for whoever reads them).
json ResultWithScanPaths(const std::vector<ScanSource>& scans, const PairResult& result,
                         PairResultFormat format) {
  json out = settings::PairResultToJson(result, format);
  out["source_path"] = scans.at(static_cast<size_t>(result.pair.source)).path;
  out["target_path"] = scans.at(static_cast<size_t>(result.pair.target)).path;
  return out;
}

}  // namespace

json PairSettings(const std::vector<ScanSource>& scans, const PairIndex& pair,
                  const BoIcpConfig& config) {
  return {{"config", PairConfigJson(config)},
          {"source", ScanSettings(scans.at(static_cast<size_t>(pair.source)))},
          {"target", ScanSettings(scans.at(static_cast<size_t>(pair.target)))}};
}

std::string PairFilePath(const std::string& out_dir, const PairIndex& pair) {
  char name[64];
  std::snprintf(name, sizeof(name), "%06d-%06d.json", pair.source, pair.target);
  return (std::filesystem::path(out_dir) / "pairs" / name).string();
}

json PairListingJson(const std::vector<ScanSource>& scans, const PairResult& result) {
  return ResultWithScanPaths(scans, result, kPairListing);
}

void WritePairFile(const std::string& out_dir, const std::vector<ScanSource>& scans,
                   const PairResult& result, const json& settings) {
  std::filesystem::create_directories(std::filesystem::path(out_dir) / "pairs");
  json out = ResultWithScanPaths(scans, result, kPairFile);
  out["settings"] = settings;
  out["format"] = kPairFileFormat;
  WriteTextFileAtomically(PairFilePath(out_dir, result.pair), out.dump(1) + "\n");
}

std::optional<PairFile> ReadPairFile(const std::string& out_dir, const PairIndex& pair) {
  const std::string path = PairFilePath(out_dir, pair);
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    json j = json::parse(in);
    MigratePairFile(j, path);
    PairFile file{settings::PairResultFromJson(j, kPairFile), j.at("settings")};
    if (!(file.result.pair == pair)) throw InputError("holds pair " + PairName(file.result.pair));
    return file;
  } catch (const NewerPairFileError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": not a pair result file (" + e.what() + ")");
  }
}

}  // namespace boicp::cli
