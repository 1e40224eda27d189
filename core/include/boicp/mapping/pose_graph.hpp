#pragma once
// From pairwise registrations to scan poses: chaining along a spanning tree,
// and pose-graph optimisation when extra pairs close loops: with calibrated
// information under a robust loss (Ceres), else Open3D's Levenberg-Marquardt
// with line processes.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "boicp/icp/pair_information.hpp"
#include "boicp/mapping/map_pairs.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// One registered pair as a pose-graph edge.
struct PairConstraint {
  PairIndex pair;
  Transform T_target_source = Transform::Identity();
  /// Weight of the edge in the optimisation; Open3D's convention (rotation
  /// first, then translation), as PlaneInformation computes it.
  InformationMatrix information = InformationMatrix::Identity();
  /// The pair's estimated probability of being right, in [0, 1]
  /// (RegistrationResult::confidence); 1 = fully trusted.
  double confidence = 1.0;
};

/// True when the constraint's confidence is below kTrustedFrom.
bool IsDoubtfulEdge(const PairConstraint& constraint);

/// Poses T_map_scan from chaining, and which constraints the chain used.
struct ChainedPoses {
  std::vector<Transform> poses;
  /// Per constraint: true if it is an edge of the spanning tree. The others
  /// close loops (and make a pose-graph optimisation worthwhile).
  std::vector<bool> in_tree;
  int loop_closures = 0;
};

/// Chains the constraints into poses with T_map_scan0 = `anchor`: a spanning
/// tree is grown from the trusted constraints in the order given (so a
/// sequential chain listed first is preferred over loop closures), then
/// from the doubtful ones, most confident first, so a doubtful pair is
/// chained only where no trusted one connects the same parts. Each pose follows T_map_source =
/// T_map_target * T_target_source along the tree. Throws InputError when a
/// scan is not reached.
ChainedPoses ChainPoses(int num_scans, const std::vector<PairConstraint>& constraints,
                        const Transform& anchor = Transform::Identity());

/// One step of a walk along a spanning tree: `scan` reached from `from`
/// over constraint `edge`.
struct TreeStep {
  int scan = 0;
  int from = 0;
  size_t edge = 0;
};

/// The tree edges (in_tree) of `constraints` walked breadth-first from scan
/// 0, whichever way each edge points: every scan reached but scan 0, each
/// after the scan it is reached from. Precondition: every index of the
/// constraints is within [0, num_scans).
std::vector<TreeStep> WalkTree(int num_scans, const std::vector<PairConstraint>& constraints,
                               const std::vector<bool>& in_tree);

struct PoseGraphOptions {
  /// Metres; the distance the edges' information matrices were computed
  /// with. Open3D derives the line-process weight of loop closures from it.
  double max_correspondence_distance = 0.5;
  double edge_prune_threshold = 0.25;    // loop closures weighted below this are dropped
  double preference_loop_closure = 1.0;  // Open3D: <1 trusts the tree more, >1 the loops
  int max_iterations = 100;
  /// Metres: the error of a registered pair's translation along one axis.
  /// Each edge's information becomes its inliers' mean information over
  /// this squared (CalibratedInformation), rather than one independent
  /// measurement per inlier, so that a chain accumulates the uncertainty
  /// pairs really have and a loop that disagrees with it by its drift is not
  /// an outlier. 0 = the information as given.
  double pair_error = 0.0;
  /// A doubtful loop closure joins the optimisation only when the initial
  /// poses agree with it: its starting line-process weight under them,
  /// (mu / (mu + r^2))^2 at full information (1 = exact agreement), must be
  /// at least this.
  double doubtful_keep_threshold = 0.5;
};

/// The information of a pair whose translation errs by `pair_error` metres
/// along each axis: `information` (a sum over the inliers, as
/// PlaneInformation gives it) divided by a third of its translation block's trace
/// (the inlier count) and by pair_error^2, plus kMinEdgeWeight /
/// pair_error^2 on the diagonal. Its rotation part keeps the inliers'
/// spread, and a direction they do not constrain stays weak.
/// Precondition: pair_error > 0.
InformationMatrix CalibratedInformation(const InformationMatrix& information, double pair_error);

/// The smallest factor a tree edge's information is scaled by, so the
/// optimisation stays well posed when a pair's confidence is 0.
constexpr double kMinEdgeWeight = 1e-3;

struct OptimizedPoses {
  std::vector<Transform> poses;  // T_map_scan, scan 0 unchanged
  std::vector<bool> kept;        // per constraint: false if pruned as an outlier loop closure
  /// Per constraint: Open3D's final line-process weight in [0, 1] (1 for
  /// certain edges), or with calibrated information the robust loss's
  /// weight; 0 for pruned or left-out loop closures.
  std::vector<double> line_process;
  /// Per constraint: why it is not kept, in a few words; empty when kept.
  std::vector<std::string> left_out_because;
};

/// The chi-square (6 degrees of freedom) a trusted loop closure's misfit
/// may reach, against the chain before the optimisation and against the
/// optimised poses after it: its 99.9 % quantile, so a right loop is left
/// out one time in a thousand.
constexpr double kLoopAgreementChi2 = 22.46;

/// Optimises the poses over all constraints, each edge's information
/// scaled by its confidence (at least kMinEdgeWeight), so a doubtful edge
/// gives way to the trusted ones around it. Tree edges (in_tree) are
/// certain. A doubtful loop closure the initial poses disagree with
/// (doubtful_keep_threshold) is left out; the others are weighed by Open3D's
/// line process, which may prune them. With every confidence 1 and no
/// options.pair_error this is Open3D's optimisation unchanged. With
/// options.pair_error set, the information is calibrated, a trusted loop
/// closure joins only when its disagreement with the chain, under both
/// their uncertainties (ChainUncertainty), is within kLoopAgreementChi2,
/// and every edge is weighed under a robust loss instead
/// (SolveRobustPoseGraph), so that an edge far off the others weighs less;
/// after the optimisation the loop closure that fits worst beyond
/// kLoopAgreementChi2 is left out in turn until all fit.
/// Preconditions: `initial` has one pose per scan and in_tree one flag per
/// constraint; a constraint naming a scan outside `initial` throws InputError.
OptimizedPoses OptimizePoseGraph(const std::vector<Transform>& initial,
                                 const std::vector<PairConstraint>& constraints,
                                 const std::vector<bool>& in_tree, const PoseGraphOptions& options);

}  // namespace boicp
