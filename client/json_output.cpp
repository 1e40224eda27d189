#include "json_output.hpp"

namespace boicp::cli {

nlohmann::json TransformToJson(const Transform& T) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 4; ++i) rows.push_back({T(i, 0), T(i, 1), T(i, 2), T(i, 3)});
  return rows;
}

nlohmann::json ConfigToJson(const BoIcpConfig& c) {
  auto triple = [](const Eigen::Vector3d& v) { return nlohmann::json{v[0], v[1], v[2]}; };
  return {{"preset", c.preset},
          {"mode", SearchModeName(c.mode)},
          {"random_samples", c.random_samples},
          {"iterations", c.iterations},
          {"voxel", c.voxel},
          {"rotation_bounds", triple(c.rotation_bounds)},
          {"translation_bounds", triple(c.translation_bounds)},
          {"max_correspondence_distance", c.EffectiveMaxCorrespondence()},
          {"objective_truncation", c.EffectiveTruncation()},
          {"icp_max_iterations", c.icp_max_iterations},
          {"evaluation_points", c.evaluation_points},
          {"coarse_icp_points", c.coarse_icp_points},
          {"finish_icp_iterations", c.finish_icp_iterations},
          {"refine_voxel", c.EffectiveRefineVoxel()},
          {"refine_max_iterations", c.refine_max_iterations},
          {"refine_candidates", c.refine_candidates},
          {"refine_source_points", c.refine_source_points},
          {"inlier_distance", c.EffectiveInlierDistance()},
          {"min_range", c.min_range},
          {"max_range", c.max_range},
          {"retry_when_doubtful", c.retry_when_doubtful},
          {"seed", c.seed},
          {"threads", c.threads}};
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
          {"confidence", r.confidence},
          {"doubtful", r.doubtful},
          {"attempts", AttemptsToJson(r.attempts)},
          {"evaluations", r.evaluations},
          {"runtime_s", r.runtime_s},
          {"gp_mean", r.gp_mean},
          {"gp_std", r.gp_std},
          {"probability_better", r.probability_better},
          {"source_points", r.source_points},
          {"target_points", r.target_points},
          {"config", ConfigToJson(r.config)},
          {"auto", auto_fields}};
}

}  // namespace boicp::cli
