#pragma once
// How sure a registration is of its answer: a logistic model over what the
// search and the refinement already measured, fitted on bench outcomes
// (bench/fit_confidence.py; bench/README.md has how it does on datasets it
// was not fitted on).

namespace boicp {

/// What the engine knows about its own answer when it finishes. The model
/// weighs fitness, log(margin) and resolution; fitness, a measured margin and
/// seen_through, constrained_share and slide_rival cap it; the rest is reported for
/// fitting and diagnosis.
struct ConfidenceFeatures {
  double fitness = 0.0;          // inlier fraction at the finest level, in [0, 1]
  double rmse_ratio = 0.0;       // inlier RMSE / inlier distance, in [0, 1]
  double margin = 0.0;           // RefinedAlignment::margin, in [0, 1]
  bool margin_measured = false;  // RefinedAlignment::margin_measured
  double support = 0.0;          // share of the first stage's runs that ended in the answer's basin
  double probability_better = 0.0;  // the surrogate's P(an unexplored start does better)
  double resolution_deg = 0.0;      // RefinedAlignment::resolution_deg
  /// SeenThroughShare of the finest source points in the target's view from
  /// its frame's origin, in [0, 1]; 0 when that view covers too few
  /// directions to say (the origin is not where a sensor stood).
  double seen_through = 0.0;
  /// ConstrainedShare of the answer's matches, in [0, 1]: how firmly its
  /// least constrained slide is held; 1 where not measured (a
  /// rung's own attempts: the result measures its answer's).
  double constrained_share = 1.0;
  /// SlideRivalShare along the answer's least constrained slide: how much
  /// of its fitness a slide off it keeps; 0 where not measured.
  double slide_rival = 0.0;
};

/// The seen_through share from which an answer has no trust at all: it puts
/// that much of the source where the target's sensor saw through.
constexpr double kSeenThroughOfNoTrust = 0.3;

/// Estimated probability, in [0, 1), that the answer is within the success
/// thresholds (2 degrees, and a few refinement voxels of translation); 0
/// with no inliers, under 0.5 with fitness under 0.05, a measured margin
/// under 0.02 or seen_through over 0.225, under 0.95 with
/// constrained_share under kUnconstrainedShare (an unconstrained direction)
/// or slide_rival over 0.88 (a slide keeps the fit), and 0 with a measured
/// margin of 0.01 or less, seen_through of 0.3 or more, constrained_share of
/// half kUnconstrainedShare or less or slide_rival of 0.92 or more.
double Confidence(const ConfidenceFeatures& features);

}  // namespace boicp
