#pragma once
// Global pose hypotheses from FPFH correspondences: the rung of the
// registration ladder that needs no initial guess. Its few hypotheses are
// refined by ICP elsewhere, so they need only land in ICP's basin.

#include <cmath>
#include <cstdint>
#include <vector>

#include "boicp/registration/fpfh_features.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

struct FeatureMatchOptions {
  // metres: a correspondence agrees with T when |T p - q| is below it (required > 0)
  double inlier_distance = 0.0;
  int iterations = 20000;  // RANSAC draws of 3 correspondences
  // a draw is kept only when every pair of its edges agrees to this ratio
  double edge_ratio = 0.9;
  int max_hypotheses = 4;  // distinct hypotheses returned, most inliers first
  // metres: hypotheses closer than this AND distinct_rotation are one (required > 0)
  double distinct_translation = 0.0;
  double distinct_rotation = 5.0 * M_PI / 180.0;  // radians
  uint64_t seed = 1;
  int threads = 1;  // the answer does not depend on it
};

struct FeatureHypothesis {
  Transform transform = Transform::Identity();  // T_target_source
  int inliers = 0;                              // correspondences within inlier_distance
};

/// Mutual nearest neighbours in FPFH space (falling back to source->target nearest neighbours when
/// fewer than ~30 are mutual), then RANSAC over those correspondences: each draw of 3 that passes
/// the edge-length check is solved by Kabsch/Umeyama (no scaling) and scored by its inlier count
/// over the correspondences only (no kd-tree over the clouds, so a draw is cheap); each accepted
/// hypothesis is re-estimated on its inliers once. Returns up to max_hypotheses distinct ones,
/// most inliers first (ties broken deterministically); empty when there are fewer than 3
/// correspondences. Throws InputError for invalid options.
///
/// `source_features` and `target_features` hold one column per point of
/// `source` and `target` (ComputeFpfhFeatures); an all-zero column (a point
/// without neighbours) is never matched. Draws whose source triangle is
/// thinner than inlier_distance are skipped too, as noise of that size could
/// turn their rotation arbitrarily. Valid options: inlier_distance > 0,
/// iterations >= 1, edge_ratio in (0, 1], max_hypotheses >= 1,
/// distinct_translation > 0, distinct_rotation >= 0, threads >= 1; InputError
/// also when a feature matrix has a column count other than its cloud's size.
std::vector<FeatureHypothesis> FeatureHypotheses(const Points& source,
                                                 const FpfhFeatures& source_features,
                                                 const Points& target,
                                                 const FpfhFeatures& target_features,
                                                 const FeatureMatchOptions& options);

}  // namespace boicp
