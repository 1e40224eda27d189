#pragma once
// The BO configuration every method of the bench derives from, so that
// methods differ only in how they find the initial transform. The shared
// downsampling and refinement are core's (boicp/refinement.hpp).

#include <string>

#include "boicp/registration/config.hpp"
#include "methods.hpp"

namespace boicp::bench {

/// N_r and N of every BO run in quick mode.
constexpr int kQuickBoSamples = 10;

/// Preset `preset` ("A", "B", "C") adapted to the dataset: the preset's N_r
/// and N (each at most kQuickBoSamples in quick mode), the dataset's bounds,
/// and a search voxel of dataset.voxel scaled by the preset's voxel relative
/// to C's (so A and B stay 7/6 coarser, as in the paper); or, with
/// dataset.automatic_settings, voxel and bounds left for RegisterPair to
/// choose from the pair. The input's seed and thread budget; the paper's
/// fixed budget (Budget::kFixed).
BoIcpConfig DatasetBoConfig(const std::string& preset, const MethodInput& input);

/// Preset C as `boicp register` runs it with no flags: settings chosen from
/// the pair and the ladder's budget (Budget::kAuto), whatever the dataset
/// table says; the input's seed and thread budget.
BoIcpConfig DatasetAutoConfig(const MethodInput& input);

/// As DatasetBoConfig, always with the dataset table's voxel and bounds: the
/// baselines' settings, which --auto-settings leaves as they are.
BoIcpConfig DatasetTableConfig(const std::string& preset, const MethodInput& input);

}  // namespace boicp::bench
