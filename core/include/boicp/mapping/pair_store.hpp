#pragma once
// Where the map pipeline keeps finished pair registrations: the daemon's
// SQLite job store, or one JSON file per pair for `boicp map`, its shards
// and `boicp merge`. The pipeline saves each pair before it reports it, so a
// run killed at any point resumes with only the unfinished pairs.

#include <vector>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/map_pairs.hpp"
#include "boicp/mapping/pose_graph.hpp"

namespace boicp {

/// What the pipeline needs of a finished pair to plan and assemble.
struct FinishedPair {
  PairIndex pair;
  Transform transform = Transform::Identity();  // T_target_source, metres
  InformationMatrix information = InformationMatrix::Identity();
  /// Pose-graph weight in [0, 1]; results stored before confidence was
  /// calibrated count as fully trusted (1).
  double confidence = 1.0;
  /// The keyframe planner's overlap estimate in [0, 1]; results stored
  /// before overlap was computed give their fitness.
  double planner_overlap = 0.0;
  /// RegistrationResult::search_reach; results stored before it was
  /// recorded give 0.
  double search_reach = 0.0;
  bool doubtful = false;  // confidence below kDoubtfulBelow
};

/// A result registered in this run, as the pipeline sees it.
FinishedPair FinishedFromResult(const PairIndex& pair, const BatchPairResult& result);

/// What the keyframe planner reads of a finished pair.
KeyframePlanner::ProbeOutcome ProbeOutcomeOf(const FinishedPair& finished);

/// The pose-graph edge of a finished pair.
PairConstraint ConstraintOf(const FinishedPair& finished);

class PairStore {
 public:
  virtual ~PairStore() = default;

  /// The pairs finished earlier with the batch's settings (a resumed job, a
  /// rerun, other shards). Called once, before any Save.
  virtual std::vector<FinishedPair> LoadFinished() = 0;

  /// Stores one pair's result durably before the pipeline reports it.
  /// `listing_order` ranks the pair in listings (plan order; keyframe probes
  /// in launch order). Called on worker threads, possibly several at once;
  /// throwing fails the run like a failed registration.
  virtual void Save(const PairIndex& pair, int listing_order, const BatchPairResult& result) = 0;

  /// Records which pairs the final poses use (the others were pruned loop
  /// closures or unused keyframe probes).
  virtual void MarkInGraph(const std::vector<PairIndex>& in_graph) = 0;
};

}  // namespace boicp
