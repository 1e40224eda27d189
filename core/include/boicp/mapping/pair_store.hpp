#pragma once
// Where the map pipeline keeps finished pair registrations: the daemon's
// SQLite job store, or one JSON file per pair for `boicp map`, its shards
// and `boicp merge`. The pipeline saves each pair before it reports it, so a
// run killed at any point resumes with only the unfinished pairs.

#include <map>
#include <string>
#include <vector>

#include "boicp/mapping/map_pairs.hpp"
#include "boicp/mapping/pair_result.hpp"

namespace boicp {

class PairStore {
 public:
  virtual ~PairStore() = default;

  /// The pairs finished earlier with the batch's settings (a resumed job, a
  /// rerun, other shards). Called once, before any Save.
  virtual std::vector<PairResult> LoadFinished() = 0;

  /// Stores one pair's result durably before the pipeline reports it.
  /// `listing_order` ranks the pair in listings (plan order; keyframe probes
  /// in launch order). Called on worker threads, possibly several at once;
  /// throwing fails the run like a failed registration.
  virtual void Save(int listing_order, const PairResult& result) = 0;

  /// Records which pairs the final poses use (the others were pruned loop
  /// closures or unused keyframe probes), and why some were left out.
  virtual void MarkInGraph(const std::vector<PairIndex>& in_graph,
                           const std::map<PairIndex, std::string>& left_out) = 0;
};

}  // namespace boicp
