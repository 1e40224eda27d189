// bo-A, bo-B, bo-C (nested) and bo-C-6dof: core's RegisterPair with the
// paper's fixed budget; bo-C-auto: the ladder, as `boicp register` runs it
// with no flags.

#include <optional>

#include "boicp/registration/bo_icp.hpp"
#include "dataset_config.hpp"
#include "evaluation_clock.hpp"
#include "methods.hpp"

namespace boicp::bench {

MethodOutput RunBoIcpWithConfig(const BoIcpConfig& config, const MethodInput& input) {
  EvaluationClock clock;
  const RegistrationResult result =
      RegisterPair(input.source, input.target, config, std::nullopt, clock.Callbacks());
  const EvaluationClock::Split split = clock.Estimate(result.runtime_s);
  MethodOutput output;
  output.transform = result.transform;
  output.confidence = result.confidence;
  output.evaluations = result.evaluations;
  output.source_points = result.source_points;
  output.target_points = result.target_points;
  output.voxel = result.config.voxel;
  output.iterations = config.iterations;
  output.features = result.features;
  output.attempts = static_cast<int>(result.attempts.size());
  for (size_t k = 1; k < result.attempts.size(); ++k)
    output.retry_s += result.attempts[k].runtime_s;
  output.answered_by = RungName(result.answered_by);
  output.attempt_details = result.attempts;
  output.icp_s = split.icp_s;
  output.model_s = split.model_s;
  return output;
}

MethodOutput RunBoIcpAuto(const MethodInput& input) {
  return RunBoIcpWithConfig(DatasetAutoConfig(input), input);
}

MethodOutput RunBoIcp(const std::string& preset, bool six_dof, const MethodInput& input) {
  BoIcpConfig config = DatasetBoConfig(preset, input);
  if (six_dof) config.mode = SearchMode::kSixDof;
  return RunBoIcpWithConfig(config, input);
}

}  // namespace boicp::bench
