#include "shared_stages.hpp"

#include <algorithm>

#include "boicp/icp.hpp"
#include "boicp/preprocess.hpp"

namespace boicp::bench {
namespace {

Points Prepare(const Points& raw, const BoIcpConfig& config, double voxel, const char* which) {
  Points sampled = VoxelDownsample(CropByRange(raw, config.min_range, config.max_range), voxel);
  if (sampled.size() < 3) {
    throw InputError(std::string(which) + " cloud has " + std::to_string(sampled.size()) +
                     " points after cropping and downsampling (need at least 3)");
  }
  return sampled;
}

IcpOptions SearchIcpOptions(const BoIcpConfig& config) {
  IcpOptions options;
  options.max_correspondence_distance = config.EffectiveMaxCorrespondence();
  options.max_iterations = config.icp_max_iterations;
  options.convergence_translation = 1e-3 * config.voxel;
  options.threads = config.threads;
  return options;
}

}  // namespace

BoIcpConfig DatasetBoConfig(const std::string& preset, const MethodInput& input) {
  BoIcpConfig config = PresetConfig(preset);
  config.voxel = input.dataset.voxel * config.voxel / PresetConfig("C").voxel;
  config.rotation_bounds = input.dataset.rotation_bounds;
  config.translation_bounds = input.dataset.translation_bounds;
  config.seed = input.seed;
  config.threads = input.threads;
  if (input.quick) {
    // The smoke test checks that every method runs, not how well.
    config.random_samples = std::min(config.random_samples, kQuickBoSamples);
    config.iterations = std::min(config.iterations, kQuickBoSamples);
  }
  return config;
}

PreparedPair PreparePair(const Points& source, const Points& target, const BoIcpConfig& config) {
  const double fine = config.EffectiveRefineVoxel();
  return {Prepare(source, config, config.voxel, "source"),
          NearestNeighborIndex(Prepare(target, config, config.voxel, "target")),
          Prepare(source, config, fine, "source"),
          NearestNeighborIndex(Prepare(target, config, fine, "target"))};
}

Transform SearchIcp(const Transform& start, const PreparedPair& pair, const BoIcpConfig& config) {
  return AlignPointToPoint(pair.search_source, pair.search_target, start, SearchIcpOptions(config))
      .transform;
}

Transform RefineCoarseToFine(const Transform& start, const PreparedPair& pair,
                             const BoIcpConfig& config) {
  IcpOptions coarse = SearchIcpOptions(config);
  coarse.max_iterations = config.refine_max_iterations;
  coarse.max_correspondence_distance = 1.5 * config.voxel;
  const Transform mid =
      AlignPointToPoint(pair.search_source, pair.search_target, start, coarse).transform;
  IcpOptions fine = coarse;
  fine.max_correspondence_distance = 3.0 * config.EffectiveRefineVoxel();
  return AlignPointToPoint(pair.fine_source, pair.fine_target, mid, fine).transform;
}

}  // namespace boicp::bench
