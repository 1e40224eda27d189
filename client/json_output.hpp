#pragma once
// JSON renderings of core results, for `--json` and the files scripts read.

#include <nlohmann/json.hpp>

#include "boicp/registration/bo_icp.hpp"

namespace boicp::cli {

/// 4x4 row-major nested array.
nlohmann::json TransformToJson(const Transform& T);

/// One object per attempt made: kind, mode, seed, fitness, confidence,
/// evaluations, refined_ends, runtime_s, kept.
nlohmann::json AttemptsToJson(const std::vector<Attempt>& attempts);

/// {"transform", "objective", "fitness", "inlier_rmse", "overlap",
///  "search_reach", "confidence", "doubtful", "seen_through",
///  "constrained_share", "unconstrained" (settings::FreeSlidesToJson), "attempts", "answered_by"
///  (RungName), "evaluations" (of every rung), "runtime_s",
///  "config" (the settings used: settings::ConfigToJson), "auto"
///  (`auto_fields`: the settings chosen from the clouds), plus GP and
///  point-count details}.
nlohmann::json RegistrationToJson(const RegistrationResult& result,
                                  const std::vector<std::string>& auto_fields);

}  // namespace boicp::cli
