#pragma once
// JSON renderings of core results, for `--json` and the files scripts read.

#include <nlohmann/json.hpp>

#include "boicp/bo_icp.hpp"

namespace boicp::cli {

/// 4x4 row-major nested array.
nlohmann::json TransformToJson(const Transform& T);

nlohmann::json ConfigToJson(const BoIcpConfig& config);

/// {"transform", "objective", "fitness", "inlier_rmse", "confidence",
///  "evaluations", "runtime_s", "config", plus GP and point-count details}.
nlohmann::json RegistrationToJson(const RegistrationResult& result, const BoIcpConfig& config);

}  // namespace boicp::cli
