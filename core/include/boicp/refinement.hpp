#pragma once
// The stages around the search that every initialiser shares: cropping and
// downsampling once per pair, and the coarse-to-fine ICP that turns a coarse
// initial transform into the final answer. BO-ICP uses them, and so does
// every baseline the bench compares it with, so that methods differ only in
// how they find the initial transform.

#include <vector>

#include "boicp/alignment_score.hpp"
#include "boicp/config.hpp"
#include "boicp/icp.hpp"
#include "boicp/nearest_neighbors.hpp"
#include "boicp/types.hpp"

namespace boicp {

/// Crops `raw` to [config.min_range, config.max_range] and voxel-downsamples it
/// at `voxel` metres. Throws InputError naming `which` ("source" or "target")
/// when fewer than 3 points are left.
Points PrepareCloud(const Points& raw, const BoIcpConfig& config, double voxel, const char* which);

/// ICP settings of one search evaluation: the config's correspondence gate and
/// iteration cap, converging once a step moves less than 1e-2 voxel and turns
/// less than 1e-3 rad.
IcpOptions SearchIcpOptions(const BoIcpConfig& config);

/// One level of the refinement pyramid.
struct PyramidLevel {
  double voxel = 0.0;           // metres
  Points source;                // at most config.refine_source_points of them (random, seeded)
  NearestNeighborIndex target;  // every point at this voxel
};

/// Both clouds of a pair at the search voxel and at every refinement level,
/// built once per pair.
struct PreparedPair {
  Points search_source;
  NearestNeighborIndex search_target;
  /// Voxels halving from config.voxel / 2 down to the refinement voxel, so
  /// every level starts inside the next level's basin; finest last.
  std::vector<PyramidLevel> pyramid;
};

/// Throws InputError when a cloud is left with fewer than 3 points at any level.
PreparedPair PreparePair(const Points& source, const Points& target, const BoIcpConfig& config);

/// A refined transform (T_target_source) and how well it fits at the finest
/// level, scored with the config's inlier distance.
struct RefinedAlignment {
  Transform transform = Transform::Identity();
  AlignmentScore score;
};

/// Coarse-to-fine point-to-point ICP from each of `starts` (T_target_source,
/// best guess first; at least one): the search clouds with a 1.5 voxel gate,
/// then each pyramid level with a gate of 3 of its voxels. Returns the start
/// that fits best at the finest level. At every level the leader (the best fit
/// so far) runs first; the others are abandoned as soon as they cannot beat
/// its truncated mean distance (clipped at 1.5 voxels of the level), so a
/// start in a wrong basin costs a few coarse iterations instead of a full run.
RefinedAlignment RefineCoarseToFine(const std::vector<Transform>& starts, const PreparedPair& pair,
                                    const BoIcpConfig& config);

}  // namespace boicp
