#pragma once
// How well a transformed source cloud lies on the target cloud.

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// Scores of T applied to a source cloud against a target index.
struct AlignmentScore {
  /// (1/n) sum_i min(d_i, tau): mean nearest-neighbour distance from each
  /// transformed source point to the target, each distance clipped at tau.
  /// This is the BO objective. Clipping bounds the cost of points with no
  /// counterpart (partial overlap, outliers) to tau, so the score ranks
  /// alignments by how much of the overlap agrees instead of by how far away
  /// the non-overlapping part happens to be.
  double truncated_mean = 0.0;
  double fitness = 0.0;      // fraction of source points with d_i < tau
  double inlier_rmse = 0.0;  // RMS of d_i over those points (0 when there are none)
};

/// Scores `source` moved by T (T_target_source) against `target`, with
/// clipping / inlier distance tau > 0 metres. Precondition: source non-empty.
AlignmentScore ScoreAlignment(const Points& source, const NearestNeighborIndex& target,
                              const Transform& T, double tau, int threads = 1);

}  // namespace boicp
