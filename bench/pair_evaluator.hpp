#pragma once
// Accuracy of an estimated transform on one benchmark pair.

#include "bench_pairs.hpp"
#include "boicp/icp/nearest_neighbors.hpp"

namespace boicp::bench {

struct PairMetrics {
  double rot_err_deg = 0.0;  // angle of R_est^T R_ref
  double trans_err_m = 0.0;  // |t_est - t_ref|
  /// Mean distance from each moved source point to its nearest target point,
  /// over the points that have one within one search voxel (the overlap), at
  /// a third of the search voxel. Unclipped distances would measure how much
  /// of the scene the two views do not share, not the alignment.
  double mean_p2p_m = 0.0;
  double overlap = 0.0;  // fraction of source points with such a neighbour
  bool success = false;  // both errors under the dataset's thresholds
};

class PairEvaluator {
 public:
  PairEvaluator(const BenchPair& pair, const DatasetSettings& settings);
  PairMetrics Evaluate(const Transform& estimate) const;

 private:
  Points source_;
  NearestNeighborIndex target_;
  Transform expected_;
  Point error_point_;
  const DatasetSettings& settings_;
};

}  // namespace boicp::bench
