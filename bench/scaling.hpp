#pragma once
// How bo-C's cost grows: against the number of points after downsampling
// (several search voxels) and against the number of BO iterations, on one pair.

#include <functional>
#include <string>
#include <vector>

#include "bench_pairs.hpp"
#include "result_row.hpp"

namespace boicp::bench {

struct ScalingPlan {
  std::vector<double> voxel_factors;  // times the dataset voxel
  std::vector<int> iterations;        // N per stage, N_r kept at the preset's
};

ScalingPlan PlanScaling(bool quick);

/// Rows with experiment "scaling-voxel" (preset C, its 3000-point evaluation
/// subsample), "scaling-voxel-all" (every downsampled point in each
/// evaluation, so ICP cost follows the point count) and "scaling-iterations".
/// In quick mode the plan is PlanScaling(true) and N_r is capped like every
/// quick BO run.
std::vector<ResultRow> RunScaling(const BenchPair& pair, const DatasetSettings& settings,
                                  int threads, bool quick,
                                  const std::function<void(const ResultRow&)>& on_row);

std::string DescribeScaling(bool quick);

}  // namespace boicp::bench
