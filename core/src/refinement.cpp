#include "boicp/refinement.hpp"

#include <string>

#include "boicp/preprocess.hpp"

namespace boicp {
namespace {

std::vector<double> RefinementVoxels(double search_voxel, double refine_voxel) {
  std::vector<double> voxels;
  for (double v = search_voxel / 2; v > refine_voxel * 1.01; v /= 2) voxels.push_back(v);
  voxels.push_back(refine_voxel);
  return voxels;
}

}  // namespace

Points PrepareCloud(const Points& raw, const BoIcpConfig& config, double voxel, const char* which) {
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

PreparedPair PreparePair(const Points& source, const Points& target, const BoIcpConfig& config) {
  PreparedPair pair{PrepareCloud(source, config, config.voxel, "source"),
                    NearestNeighborIndex(PrepareCloud(target, config, config.voxel, "target")),
                    {}};
  for (double voxel : RefinementVoxels(config.voxel, config.EffectiveRefineVoxel())) {
    pair.pyramid.push_back({voxel, PrepareCloud(source, config, voxel, "source"),
                            NearestNeighborIndex(PrepareCloud(target, config, voxel, "target"))});
  }
  return pair;
}

RefinedAlignment RefineCoarseToFine(const Transform& start, const PreparedPair& pair,
                                    const BoIcpConfig& config) {
  IcpOptions options = SearchIcpOptions(config);
  options.max_iterations = config.refine_max_iterations;
  options.max_correspondence_distance = 1.5 * config.voxel;
  Transform T = AlignPointToPoint(pair.search_source, pair.search_target, start, options).transform;
  for (const PyramidLevel& level : pair.pyramid) {
    options.max_correspondence_distance = 3.0 * level.voxel;
    options.convergence_translation = 1e-3 * level.voxel;
    T = AlignPointToPoint(level.source, level.target, T, options).transform;
  }
  const PyramidLevel& finest = pair.pyramid.back();
  return {T, ScoreAlignment(finest.source, finest.target, T, config.EffectiveInlierDistance(),
                            config.threads)};
}

}  // namespace boicp
