#include "json_output.hpp"

#include "boicp/settings/pair_result_json.hpp"
#include "boicp/settings/settings_json.hpp"

namespace boicp::cli {

nlohmann::json TransformToJson(const Transform& T) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 4; ++i) rows.push_back({T(i, 0), T(i, 1), T(i, 2), T(i, 3)});
  return rows;
}

nlohmann::json AttemptsToJson(const std::vector<Attempt>& attempts) {
  nlohmann::json out = nlohmann::json::array();
  for (const Attempt& a : attempts) {
    out.push_back({{"kind", AttemptKindName(a.kind)},
                   {"mode", SearchModeName(a.mode)},
                   {"seed", a.seed},
                   {"fitness", a.fitness},
                   {"confidence", a.confidence},
                   {"evaluations", a.evaluations},
                   {"refined_ends", a.refined_ends},
                   {"runtime_s", a.runtime_s},
                   {"kept", a.kept}});
  }
  return out;
}

nlohmann::json RegistrationToJson(const RegistrationResult& r,
                                  const std::vector<std::string>& auto_fields) {
  return {{"transform", TransformToJson(r.transform)},
          {"objective", r.objective},
          {"fitness", r.fitness},
          {"inlier_rmse", r.inlier_rmse},
          {"overlap", r.overlap},
          {"search_reach", r.search_reach},
          {"confidence", r.confidence},
          {"seen_through", r.features.seen_through},
          {"constrained_share", r.features.constrained_share},
          {"slide_rival", r.features.slide_rival},
          {"unconstrained", settings::FreeSlidesToJson(r.unconstrained)},
          {"doubtful", r.doubtful},
          {"attempts", AttemptsToJson(r.attempts)},
          {"answered_by", RungName(r.answered_by)},
          {"evaluations", r.evaluations},
          {"runtime_s", r.runtime_s},
          {"gp_mean", r.gp_mean},
          {"gp_std", r.gp_std},
          {"probability_better", r.probability_better},
          {"source_points", r.source_points},
          {"target_points", r.target_points},
          {"config", settings::ConfigToJson(r.config)},
          {"auto", auto_fields}};
}

}  // namespace boicp::cli
