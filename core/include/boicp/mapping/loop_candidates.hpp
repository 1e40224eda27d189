#pragma once
// Loop-closure candidates found on a chained trajectory: scans far apart
// along the drive whose views lie within reach of each other under the
// chain, the reach growing with the distance driven between them, since
// that is how far the chain may have drifted.

#include <vector>

#include "boicp/mapping/map_pairs.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// Whether a map looks for loops on its own.
enum class LoopSearch {
  kAuto,  ///< candidates from the chained poses, verified by registration
  kOff,   ///< only the pairs the plan lists
};

/// "auto" or "off".
std::string LoopSearchName(LoopSearch search);

/// The search a name gives; throws InputError naming `field` for any other word.
LoopSearch LoopSearchFromName(const std::string& name, const std::string& field);

struct LoopCandidateOptions {
  /// Scans closer than this along the sequence are never candidates: the
  /// chain already ties them together.
  int min_sequence_gap = 10;
  /// Metres two views may lie apart before any drift: a registration
  /// centred on the chain's relative pose still finds the other scan
  /// within its translation box.
  double reach = 1.0;
  /// The reach grows by this fraction of the path driven between the two
  /// scans (odometry-like drift).
  double drift_per_metre = 0.05;
  /// At most this many candidates for each later scan.
  int max_per_scan = 1;
  /// A candidate within this many scans of a kept one at both of its ends
  /// is dropped: one loop closure per revisit stretch is enough.
  int min_spacing = 5;
  /// At most this many candidates per scan of the drive in all, the best
  /// first, so that verifying them costs a bounded share of the chain.
  double max_per_drive_scan = 0.25;
};

struct LoopCandidate {
  PairIndex pair;  ///< source: the later scan; target: the earlier one
  /// The chained poses' T_target_source: the prior its registration is centred on.
  Transform prior = Transform::Identity();
  double distance = 0.0;  ///< metres between the two views under the chain
  double reach = 0.0;     ///< metres they were allowed to lie apart
  double path = 0.0;      ///< metres driven from one to the other along the chain
};

/// Candidates among scans with chained poses `poses` (T_map_scan), each scan
/// seen from `view_centres` (map frame, metres: where the scan's points lie,
/// e.g. their centroid moved by the pose). Pairs within reach are ranked by
/// the path driven between them (the drift a loop can take out) times one
/// less their distance over reach, and taken greedily under the
/// per-scan cap, the spacing and the drive's budget (at least one), so the
/// count grows with the revisits, not with the square of the scans. Sorted
/// by (source, target). Preconditions: one view centre per pose; options'
/// counts >= 1 and lengths >= 0.
std::vector<LoopCandidate> LoopCandidatesFromPoses(const std::vector<Transform>& poses,
                                                   const std::vector<Point>& view_centres,
                                                   const LoopCandidateOptions& options);

}  // namespace boicp
