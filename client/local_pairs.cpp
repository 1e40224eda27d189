#include "local_pairs.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "boicp/settings/rung_summary.hpp"
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
  out["prior_pose"] = scan.prior_pose ? TransformToJson(*scan.prior_pose) : json(nullptr);
  return out;
}

Transform TransformFromJson(const json& rows) {
  Transform T;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j)
      T(i, j) = rows.at(static_cast<size_t>(i)).at(static_cast<size_t>(j)).get<double>();
  }
  return T;
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

// A pair file's answered_by: one of RungName's words.
Rung RungOfFile(const json& value) {
  const std::string name = value.get<std::string>();
  const std::optional<Rung> rung = settings::RungFromName(name);
  if (!rung) throw InputError("answered_by: unknown rung '" + name + "'");
  return *rung;
}

// null for unknown.
template <typename T>
std::optional<T> OptionalOf(const json& value) {
  if (value.is_null()) return std::nullopt;
  return value.get<T>();
}

// Pair files without a "format" (written before there was one) lack the
// keys added since: they read as unknown (doubtful, overlap, search_reach),
// the full search (answered_by, as every pair was before the ladder) and the
// settings under today's names. Files of a later format are refused, not
// misread.
void MigratePairFile(json& j, const std::string& path) {
  const int format = j.value("format", 0);
  if (format > kPairFileFormat) {
    throw NewerPairFileError(path + ": format " + std::to_string(format) +
                             " is newer than this boicp reads (" + std::to_string(kPairFileFormat) +
                             "); use the boicp that wrote it");
  }
  if (format == kPairFileFormat) return;
  for (const char* key : {"doubtful", "overlap", "search_reach"}) {
    if (!j.contains(key)) j[key] = nullptr;
  }
  if (!j.contains("answered_by")) j["answered_by"] = RungName(Rung::kFullSearch);
  UpgradeOldPairConfig(j.at("settings").at("config"), path);
  j["format"] = kPairFileFormat;
}

}  // namespace

json PairSettings(const std::vector<ScanSource>& scans, const PairIndex& pair,
                  const BoIcpConfig& config) {
  return {{"config", PairConfigJson(config)},
          {"source", ScanSettings(scans.at(static_cast<size_t>(pair.source)))},
          {"target", ScanSettings(scans.at(static_cast<size_t>(pair.target)))}};
}

PairRecord MakePairRecord(const std::vector<ScanSource>& scans, const PairIndex& pair,
                          const BatchPairResult& result, json settings) {
  const RegistrationResult& r = result.registration;
  PairRecord record;
  record.pair = pair;
  record.source_path = scans.at(static_cast<size_t>(pair.source)).path;
  record.target_path = scans.at(static_cast<size_t>(pair.target)).path;
  record.transform = r.transform;
  record.objective = r.objective;
  record.fitness = r.fitness;
  record.inlier_rmse = r.inlier_rmse;
  record.confidence = r.confidence;
  record.overlap = r.overlap;
  record.search_reach = r.search_reach;
  record.doubtful = r.doubtful;
  record.answered_by = r.answered_by;
  record.evaluations = r.evaluations;
  record.runtime_s = r.runtime_s;
  record.seed = result.seed;
  record.information = r.information;
  record.settings = std::move(settings);
  return record;
}

std::string PairFilePath(const std::string& out_dir, const PairIndex& pair) {
  char name[64];
  std::snprintf(name, sizeof(name), "%06d-%06d.json", pair.source, pair.target);
  return (std::filesystem::path(out_dir) / "pairs" / name).string();
}

json PairRecordToJson(const PairRecord& r) {
  return {{"source", r.pair.source},
          {"target", r.pair.target},
          {"source_path", r.source_path},
          {"target_path", r.target_path},
          {"transform", TransformToJson(r.transform)},
          {"objective", r.objective},
          {"fitness", r.fitness},
          {"inlier_rmse", r.inlier_rmse},
          {"confidence", r.confidence},
          {"doubtful", IsDoubtful(r)},
          {"overlap", r.overlap ? json(*r.overlap) : json(nullptr)},
          {"search_reach", r.search_reach ? json(*r.search_reach) : json(nullptr)},
          {"answered_by", RungName(r.answered_by)},
          {"evaluations", r.evaluations},
          {"runtime_s", r.runtime_s},
          {"seed", r.seed}};
}

bool IsDoubtful(const PairRecord& record) { return record.doubtful.value_or(false); }

double PlannerOverlap(const PairRecord& record) { return record.overlap.value_or(record.fitness); }

PairConstraint RecordConstraint(const PairRecord& record) {
  return {record.pair, record.transform, record.information,
          record.doubtful ? record.confidence : 1.0};
}

void WritePairFile(const std::string& out_dir, const PairRecord& record) {
  std::filesystem::create_directories(std::filesystem::path(out_dir) / "pairs");
  json out = PairRecordToJson(record);
  json information = json::array();
  for (int i = 0; i < 6; ++i) {
    json row = json::array();
    for (int j = 0; j < 6; ++j) row.push_back(record.information(i, j));
    information.push_back(row);
  }
  out["information"] = information;
  out["settings"] = record.settings;
  out["format"] = kPairFileFormat;
  WriteTextFileAtomically(PairFilePath(out_dir, record.pair), out.dump(1) + "\n");
}

std::optional<PairRecord> ReadPairFile(const std::string& out_dir, const PairIndex& pair) {
  const std::string path = PairFilePath(out_dir, pair);
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    json j = json::parse(in);
    MigratePairFile(j, path);
    PairRecord r;
    r.pair = {j.at("source").get<int>(), j.at("target").get<int>()};
    if (!(r.pair == pair))
      throw InputError("holds pair " + std::to_string(r.pair.source) + "->" +
                       std::to_string(r.pair.target));
    r.source_path = j.at("source_path").get<std::string>();
    r.target_path = j.at("target_path").get<std::string>();
    r.transform = TransformFromJson(j.at("transform"));
    r.objective = j.at("objective").get<double>();
    r.fitness = j.at("fitness").get<double>();
    r.inlier_rmse = j.at("inlier_rmse").get<double>();
    r.confidence = j.at("confidence").get<double>();
    r.doubtful = OptionalOf<bool>(j.at("doubtful"));
    r.overlap = OptionalOf<double>(j.at("overlap"));
    r.search_reach = OptionalOf<double>(j.at("search_reach"));
    r.answered_by = RungOfFile(j.at("answered_by"));
    r.evaluations = j.at("evaluations").get<int>();
    r.runtime_s = j.at("runtime_s").get<double>();
    r.seed = j.at("seed").get<uint64_t>();
    for (int i = 0; i < 6; ++i) {
      for (int k = 0; k < 6; ++k) {
        r.information(i, k) =
            j.at("information").at(static_cast<size_t>(i)).at(static_cast<size_t>(k)).get<double>();
      }
    }
    r.settings = j.at("settings");
    return r;
  } catch (const NewerPairFileError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": not a pair result file (" + e.what() + ")");
  }
}

}  // namespace boicp::cli
