#include "dataset_config.hpp"

#include <algorithm>

namespace boicp::bench {

BoIcpConfig DatasetBoConfig(const std::string& preset, const MethodInput& input) {
  BoIcpConfig config = PresetConfig(preset);
  config.retry_when_doubtful = input.dataset.retry_when_doubtful;
  if (!input.dataset.automatic_settings) {
    config.automatic.clear();
    config.voxel = input.dataset.voxel * config.voxel / PresetConfig("C").voxel;
    config.rotation_bounds = input.dataset.rotation_bounds;
    config.translation_bounds = input.dataset.translation_bounds;
  }
  config.seed = input.seed;
  config.threads = input.threads;
  if (input.quick) {
    // The smoke test checks that every method runs, not how well.
    config.random_samples = std::min(config.random_samples, kQuickBoSamples);
    config.iterations = std::min(config.iterations, kQuickBoSamples);
  }
  return config;
}

}  // namespace boicp::bench
