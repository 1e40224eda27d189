#pragma once
// Loop-closure candidates: scans far apart along the drive that may see one
// place. Found two ways: on the chained trajectory (views within reach of
// each other, the reach growing with the distance driven between them,
// since that is how far the chain may have drifted), and by place
// recognition, which holds however far the chain drifted or broke.

#include <string>
#include <vector>

#include "boicp/mapping/map_pairs.hpp"
#include "boicp/mapping/place_recognition.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// Whether a map looks for loops on its own.
enum class LoopSearch {
  kAuto,  ///< candidates from the chained poses and by place, verified by registration
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
  /// The same budget for candidates found by place recognition, on top: a
  /// drive's best-looking pairs are proposed whether or not it comes back,
  /// so this budget is what a drive without revisits spends.
  double max_place_per_drive_scan = 0.05;
  /// Place recognition compares each scan in full with this many earlier
  /// scans, those whose ring keys (PlaceDescriptor) are nearest.
  int place_shortlist = 10;
};

/// How a loop candidate was found (PairResult::found_by names it).
enum class LoopFoundBy {
  kPoses,  ///< "poses": the views lie within reach under the chained poses
  kPlace,  ///< "place": the scans' place descriptors match
};

/// "poses" or "place".
std::string LoopFoundByName(LoopFoundBy found_by);

struct LoopCandidate {
  PairIndex pair;  ///< source: the later scan; target: the earlier one
  /// T_target_source its registration is centred on: the chained poses', or
  /// the place match's heading (PlacePrior).
  Transform prior = Transform::Identity();
  LoopFoundBy found_by = LoopFoundBy::kPoses;
  double distance = 0.0;        ///< poses: metres between the two views under the chain
  double reach = 0.0;           ///< poses: metres they were allowed to lie apart
  double path = 0.0;            ///< poses: metres driven from one to the other along the chain
  double place_distance = 1.0;  ///< place: PlaceMatch::distance
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

/// Candidates among scans described by `places` (one per scan, empty for a
/// scan that does not see all around), each sensor at `sensor_origins` in
/// its scan's frame, joining only scans of different `pieces` (one label
/// per scan: the scans trusted pairs already connect share one). Within a
/// piece the chained poses know where each scan is, and a place that looks
/// alike but lies elsewhere is more likely a look-alike street than a loop.
/// Each later scan is matched (MatchPlaces) with the earlier scans of other
/// pieces whose ring keys are nearest and keeps its best; these are taken
/// most alike first under the per-scan cap, the spacing (also from every
/// pair of `taken`, e.g. the candidates from poses) and the drive's place
/// budget (at least one). No pair closer than min_sequence_gap along the
/// sequence. Of several drives (`drive_starts`, drives.hpp), each has its
/// own budget, the gap holds within a drive only, and pairs that join two
/// drives are taken first. Sorted by (source, target). Preconditions: one
/// origin and one piece per descriptor; non-empty descriptors of one grid;
/// options as above.
std::vector<LoopCandidate> LoopCandidatesFromPlaces(const std::vector<PlaceDescriptor>& places,
                                                    const std::vector<Point>& sensor_origins,
                                                    const std::vector<int>& pieces,
                                                    const std::vector<PairIndex>& taken,
                                                    const LoopCandidateOptions& options,
                                                    const std::vector<int>& drive_starts = {});

}  // namespace boicp
