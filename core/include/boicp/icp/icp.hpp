#pragma once
// ICP against a prebuilt target index: point-to-point (Besl & McKay) and
// point-to-plane (Chen & Medioni), which share everything but the step.

#include <limits>
#include <vector>

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

struct IcpOptions {
  double max_correspondence_distance = 1.0;  // metres; pairs farther apart are ignored
  int max_iterations = 30;
  double convergence_translation = 1e-4;  // metres: stop once a step moves less than this...
  double convergence_rotation = 1e-4;     // ...and rotates less than this (radians)
  int threads = 1;  // for the nearest-neighbour searches; results do not depend on it

  // Abandoning runs that cannot win. When abandon_above is finite, every
  // iteration also measures the truncated mean distance (each point's
  // distance clipped at `truncation` metres, which must not exceed the gate)
  // and the run stops once even the limit projected from its recent progress
  // stays above abandon_above (see ProjectedLimit). The refinement gives up
  // on candidates that head for a worse fit than its leader this way, long
  // before they converge.
  double abandon_above = std::numeric_limits<double>::infinity();  // metres
  double truncation = 0.0;                                         // metres
  int abandon_after = 5;  // iterations always run before a run may be abandoned

  // How close a run must come to a known end (see AlignPointToPoint) to stop
  // there: translation (metres) and angle (radians) of T_end^-1 * T. 0 = never.
  double join_translation = 0.0;
  double join_rotation = 0.0;

  // Where a surface lets ICP slide (a street, a long wall), point-to-point
  // steps creep along it, each a little shorter than the last. With
  // `extrapolate`, two steps in nearly the same direction, the second the
  // shorter, are followed by a jump over what the geometric series of such
  // steps would still cover (Besl and McKay's accelerated ICP), at most
  // kMaxExtrapolation steps long. A jump that leaves the truncated mean
  // distance (clipped at `truncation`, or at the gate when that is 0) above
  // its value before the jump is undone, and the run jumps no more. The
  // answer moves only within the convergence tolerances; the iterations fall.
  bool extrapolate = false;
};

/// Longest jump of an extrapolating ICP run, in steps.
constexpr double kMaxExtrapolation = 8.0;

/// Outcome of one ICP run. `transform` is T_target_source: p_target = T * p_source.
struct IcpResult {
  Transform transform = Transform::Identity();
  int iterations = 0;
  bool converged = false;      // the step criterion was met before max_iterations
  size_t correspondences = 0;  // in the last iteration
  double rmse = 0.0;           // of the last iteration's correspondences, metres
  bool abandoned = false;      // stopped because it could not beat options.abandon_above
  int joined_end = -1;         // index into known_ends of the end it stopped at, or -1
};

/// Rigid transform that best maps the `source` points onto their paired
/// `target` points in the least-squares sense (Kabsch / Umeyama without scale),
/// from the sums of one iteration. Precondition: count >= 3, not collinear.
Transform RigidFromCrossCovariance(const Point& source_mean, const Point& target_mean,
                                   const Eigen::Matrix3d& cross_covariance);

/// The lowest value a decreasing sequence can reach in `remaining_steps` more
/// steps if no step falls faster than the faster of its last two, from its
/// last three values (oldest first): f2 - max(f0 - f1, f1 - f2, 0) * remaining.
/// ICP slides into a basin at a roughly steady or slowing pace, so a run whose
/// bound stays above the incumbent is not going to beat it.
double ProjectedLimit(double f0, double f1, double f2, int remaining_steps);

/// Runs ICP from `initial`. Allocates its scratch buffers once per call, never
/// per iteration. With fewer than 3 correspondences it stops and returns the
/// last transform with converged = false.
///
/// `known_ends` are where earlier runs on the same problem converged. A
/// converged end attracts the runs that pass close to it, so once this run
/// comes within options.join_translation and options.join_rotation of one it
/// stops and returns that end (the nearest in translation) as converged, with
/// joined_end set, instead of crawling through the same last small steps.
IcpResult AlignPointToPoint(const Points& source, const NearestNeighborIndex& target,
                            const Transform& initial, const IcpOptions& options,
                            const std::vector<Transform>& known_ends = {});

/// Point-to-plane ICP: the same contract as AlignPointToPoint, but each step
/// minimises the distances to the matched points' tangent planes, which
/// slides along surfaces and so converges in far fewer iterations on
/// structured scenes. `target_normals` (EstimateSurfaceNormals) has one entry
/// per target point; zero normals are ignored. Throws InputError when the
/// sizes differ.
IcpResult AlignPointToPlane(const Points& source, const NearestNeighborIndex& target,
                            const Points& target_normals, const Transform& initial,
                            const IcpOptions& options,
                            const std::vector<Transform>& known_ends = {});

}  // namespace boicp
