#pragma once
// Whether an answer is the only place its surfaces fit along its weakest
// slide: on a street of look-alike facades, ground and facades fit as well
// a block further on, and the answer's own spot is one of many.

#include <cstddef>

#include <Eigen/Core>

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// Slides shorter than this many inlier distances stay in the answer's own
/// basin (the success thresholds are a few refinement voxels).
constexpr double kRivalSlideStart = 4.0;

/// Nor do slides shorter than this share of the source's extent along the
/// slide: a dense scan's inlier distance is millimetres, and a slide of a
/// few of them keeps most of any smooth surface's fit.
constexpr double kRivalSlideShare = 0.05;

/// Source points enough to measure a share to about 0.01 (binomial error of
/// a fitness near 1/2); a finer level's more would only cost time.
constexpr size_t kSlideRivalPoints = 2000;

/// The highest fitness of `source` moved by T_target_source and then slid
/// along the unit `axis` (target frame), either way, by kRivalSlideStart
/// inlier distances or kRivalSlideShare of the source's extent along the
/// axis (its 90th percentile of distance from its mean), whichever is
/// longer, up to that extent, divided by the answer's own
/// fitness (inliers within `inlier_distance` metres). Near 1: a slide keeps
/// the fit, so nothing the scans share pins the answer where it is. 0 when
/// the answer has no inliers or the source is too short along the axis to
/// slide. Preconditions: source non-empty, inlier_distance > 0.
double SlideRivalShare(const Points& source, const NearestNeighborIndex& target,
                       const Transform& T_target_source, const Eigen::Vector3d& axis,
                       double inlier_distance);

}  // namespace boicp
