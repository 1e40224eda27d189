#include "boicp/refinement.hpp"

#include <algorithm>
#include <limits>
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
  // A search only has to tell basins apart: steps of 1/100 voxel and 1e-3 rad
  // are far below that need (measured on the bench pairs: the same success,
  // with a fifth fewer iterations than 1/1000 voxel and 1e-4 rad).
  options.convergence_translation = 1e-2 * config.voxel;
  options.convergence_rotation = 1e-3;
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

RefinedAlignment RefineCoarseToFine(const std::vector<Transform>& starts, const PreparedPair& pair,
                                    const BoIcpConfig& config) {
  if (starts.empty()) throw InputError("refinement needs at least one start");
  struct Candidate {
    Transform T;
    double score;  // truncated mean at the last level run
  };
  std::vector<Candidate> alive;
  for (const Transform& start : starts) alive.push_back({start, 0.0});

  IcpOptions options = SearchIcpOptions(config);
  options.max_iterations = config.refine_max_iterations;
  // The answer's accuracy is decided here: run each level until its steps
  // are below 1/1000 voxel and 1e-4 rad (the search's 1/100 voxel and 1e-3
  // rad cost the bunny 0.2-0.5 degrees and one flipped pair).
  options.convergence_rotation = 1e-4;
  // The search level first, then the pyramid, finest last.
  const auto run_level = [&](const Points& source, const NearestNeighborIndex& target, double voxel,
                             double gate) {
    options.max_correspondence_distance = gate;
    options.convergence_translation = 1e-3 * voxel;
    options.truncation = 1.5 * voxel;
    std::vector<Candidate> survivors;
    for (size_t k = 0; k < alive.size(); ++k) {
      options.abandon_above = k == 0 ? std::numeric_limits<double>::infinity() : survivors[0].score;
      const IcpResult icp = AlignPointToPoint(source, target, alive[k].T, options);
      if (icp.abandoned) continue;
      survivors.push_back(
          {icp.transform,
           ScoreAlignment(source, target, icp.transform, options.truncation).truncated_mean});
    }
    // Leader of the next level first; the sort is stable so ties keep the search's order.
    std::stable_sort(survivors.begin(), survivors.end(),
                     [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
    alive = std::move(survivors);
  };
  run_level(pair.search_source, pair.search_target, config.voxel, 1.5 * config.voxel);
  for (const PyramidLevel& level : pair.pyramid) {
    run_level(level.source, level.target, level.voxel, 3.0 * level.voxel);
  }
  const PyramidLevel& finest = pair.pyramid.back();
  const Transform& best = alive.front().T;
  return {best,
          ScoreAlignment(finest.source, finest.target, best, config.EffectiveInlierDistance())};
}

}  // namespace boicp
