#pragma once
// Stages that every method shares with core's RegisterPair, so that the
// methods differ only in how they find the initial transform: the dataset's
// BO config, search/fine downsampling, and the coarse-to-fine ICP refinement.
// core keeps these inside bo_icp.cpp; the bench mirrors them here.

#include <string>

#include "boicp/config.hpp"
#include "boicp/nearest_neighbors.hpp"
#include "boicp/types.hpp"
#include "methods.hpp"

namespace boicp::bench {

/// N_r and N of every BO run in quick mode.
constexpr int kQuickBoSamples = 10;

/// Preset `preset` ("A", "B", "C") adapted to the dataset: the preset's N_r
/// and N (each at most kQuickBoSamples in quick mode), the dataset's bounds,
/// and a search voxel of dataset.voxel scaled by the preset's voxel relative
/// to C's (so A and B stay 7/6 coarser, as in the paper); the input's seed and
/// thread budget.
BoIcpConfig DatasetBoConfig(const std::string& preset, const MethodInput& input);

/// Both clouds at the search voxel and at the refinement voxel, with target indices.
struct PreparedPair {
  Points search_source;
  NearestNeighborIndex search_target;
  Points fine_source;
  NearestNeighborIndex fine_target;
};

/// Crops and voxel-downsamples as RegisterPair does. Throws InputError when a
/// cloud is left with fewer than 3 points.
PreparedPair PreparePair(const Points& source, const Points& target, const BoIcpConfig& config);

/// One search-level ICP run from `start` (what a BO evaluation runs).
Transform SearchIcp(const Transform& start, const PreparedPair& pair, const BoIcpConfig& config);

/// RegisterPair's refinement: ICP at the search voxel with a 1.5 voxel gate,
/// then on the refinement voxel with a 3 refine-voxel gate.
Transform RefineCoarseToFine(const Transform& start, const PreparedPair& pair,
                             const BoIcpConfig& config);

}  // namespace boicp::bench
