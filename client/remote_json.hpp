#pragma once
// JSON renderings of the daemon's jobs and results, for `jobs --json` and
// `show --json`. Field names follow the proto (snake_case); states are
// lowercase words; transforms are 4x4 row-major nested arrays.

#include <string>

#include <nlohmann/json.hpp>

#include "boicp/rpc/proto_convert.hpp"

namespace boicp::cli {

/// {"job_id", "label", "state", "stage", "pairs_done", "pairs_total", "pairs_doubtful",
///  "num_scans", "stage_done", "stage_total", "eta_seconds", "created_at",
///  "started_at", "finished_at", "error", "cancel_requested",
///  "pose_graph_optimised"}; times are Unix seconds (0 = not yet).
/// A job's chosen settings: the registration settings the API carries, as
/// settings::UsedSettingsToJson writes them (the keys of run.json's
/// "chosen"), map_resolution, map_max_range and "auto" (the names of the
/// fields chosen from the scans).
nlohmann::json ChosenSettingsToJson(const v1::ChosenSettings& settings);

/// The same on one line, for `boicp show`.
std::string DescribeChosenSettings(const v1::ChosenSettings& settings);

nlohmann::json JobToJson(const v1::Job& job);

/// The pair's kPairApi fields (settings::PairResultToJson: "source",
/// "target", "transform" as T_target_source, "confidence", "doubtful",
/// "answered_by", "finished_at", "in_graph", ...) and its "source_scan_id"
/// and "target_scan_id". Throws InputError for a malformed message.
nlohmann::json PairToJson(const v1::PairResult& pair);

/// The job's fields plus "pairs" (in plan order) and "trajectory"
/// ([{"index", "scan_id", "timestamp", "pose" (T_map_scan)}], empty until
/// the job succeeded).
nlohmann::json ResultsToJson(const v1::JobResults& results);

}  // namespace boicp::cli
