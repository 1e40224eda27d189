#pragma once
// How far a map's trajectory is from a reference: the absolute trajectory
// error after a rigid alignment (no scale), and the relative drift over
// stretches of the reference path.

#include <optional>
#include <vector>

#include "boicp/util/types.hpp"

namespace boicp {

struct TrajectoryError {
  int scans = 0;                 ///< scans with a reference pose (at least 3 to align)
  double ate_rmse = 0.0;         ///< metres, positions after the best rigid alignment
  double ate_max = 0.0;          ///< metres
  std::vector<double> per_scan;  ///< metres per scan; NaN where there is no reference
  double segment = 0.0;          ///< metres of reference path a drift is measured over
  int segments = 0;              ///< stretches measured (none on a path shorter than `segment`)
  /// Mean translation error of the pose `segment` metres of reference path
  /// on, relative to each scan, over that path length: 0.01 = 1 cm per metre.
  double drift_per_metre = 0.0;
};

/// Compares `poses` (T_map_scan) with `reference` (T_world_scan, where
/// known), scan by scan. `segment` metres <= 0: a tenth of the reference
/// path. Throws InputError when the counts differ or fewer than 2 scans
/// have a reference.
TrajectoryError CompareTrajectories(const std::vector<Transform>& poses,
                                    const std::vector<std::optional<Transform>>& reference,
                                    double segment = 0.0);

}  // namespace boicp
