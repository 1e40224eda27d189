#include "dataset_config.hpp"

#include <algorithm>

#include "boicp/settings/requested_settings.hpp"

namespace boicp::bench {

namespace {

BoIcpConfig PresetForDataset(const std::string& preset, const MethodInput& input, bool automatic) {
  const BoIcpConfig preset_config = PresetConfig(preset);
  settings::RequestedSettings given;
  given.preset = preset;
  given.seed = input.seed;
  given.threads = input.threads;
  given.no_retry = !input.dataset.retry_when_doubtful;
  given.icp_objective = input.dataset.icp_objective;
  if (!automatic) {
    given.fixed_settings = true;
    given.voxel = input.dataset.voxel * preset_config.voxel / PresetConfig("C").voxel;
    given.rotation_bounds = input.dataset.rotation_bounds;
    given.translation_bounds = input.dataset.translation_bounds;
  }
  if (input.quick) {
    // The smoke test checks that every method runs, not how well.
    given.random_samples = std::min(preset_config.random_samples, kQuickBoSamples);
    given.iterations = std::min(preset_config.iterations, kQuickBoSamples);
  }
  BoIcpConfig config = settings::ConfigFromSettings(given);
  config.budget = Budget::kFixed;
  return config;
}

}  // namespace

BoIcpConfig DatasetBoConfig(const std::string& preset, const MethodInput& input) {
  return PresetForDataset(preset, input, input.dataset.automatic_settings);
}

BoIcpConfig DatasetAutoConfig(const MethodInput& input) {
  BoIcpConfig config = PresetForDataset("C", input, /*automatic=*/true);
  config.budget = Budget::kAuto;
  return config;
}

BoIcpConfig DatasetTableConfig(const std::string& preset, const MethodInput& input) {
  BoIcpConfig config = PresetForDataset(preset, input, false);
  // The baselines run no search evaluations, so PreparePair estimates no
  // target normals for them.
  config.icp_objective = IcpObjective::kPointToPoint;
  return config;
}

}  // namespace boicp::bench
