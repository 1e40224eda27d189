#pragma once
// Which slides a registered pair's surfaces do not pin down: along a wall, a
// corridor or a floor. Measured from the matches' information, not guessed
// from the scene.

#include <vector>

#include "boicp/icp/pair_information.hpp"

namespace boicp {

/// One principal slide of a pair's matches.
struct FreeSlide {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // unit, in the target's frame
  /// How much of a slide along `axis` is across the matched surfaces (its
  /// mean squared displacement off them, per unit of slide squared), in
  /// [0, 1]: 1/3 for surfaces facing every way, 0 along a corridor.
  double across_share = 0.0;
  /// Metres: how far the slide goes before the matches' RMS distance to
  /// their surfaces reaches the inlier distance; at most kFreeSlideBound.
  double extent = 0.0;
};

/// The largest extent reported: beyond it nothing says how free a slide is.
constexpr double kFreeSlideBound = 1000.0;  // metres

/// A slide is unconstrained when less than this share of it is across the
/// matched surfaces: sliding 10 inlier distances moves the matches off
/// their surfaces by one on average, which a rival basin's fitness hides.
constexpr double kUnconstrainedShare = 0.01;

/// The three principal slides of PlaneInformation's `information` (the
/// translation block's eigenvectors; each match with a normal adds 1 to its
/// trace), the least constrained first. Empty without matches.
/// Precondition: inlier_distance > 0.
std::vector<FreeSlide> PrincipalSlides(const InformationMatrix& information,
                                       double inlier_distance);

/// The slides of PrincipalSlides whose across_share is under
/// kUnconstrainedShare.
std::vector<FreeSlide> UnconstrainedSlides(const InformationMatrix& information,
                                           double inlier_distance);

/// The least constrained slide's across_share, 0 without matches: how
/// firmly the weakest direction is held.
double ConstrainedShare(const InformationMatrix& information);

}  // namespace boicp
