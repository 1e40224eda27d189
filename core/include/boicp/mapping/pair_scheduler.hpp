#pragma once
// The registration stage of the map pipeline: which pair runs when, on
// whose threads, and what is stored and reported as each one finishes. The
// daemon and `boicp map` both schedule through here, so both register the
// same pairs and (each pair having its own seed) get the same results
// whatever the number of threads.

#include <functional>
#include <map>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/map_pairs.hpp"
#include "boicp/mapping/map_progress.hpp"
#include "boicp/mapping/pair_scale.hpp"
#include "boicp/mapping/pair_store.hpp"
#include "boicp/registration/config.hpp"

namespace boicp {

/// How pair registrations run.
struct PairExecution {
  /// Runs a task on a worker thread, later; e.g. ThreadPool::Submit.
  std::function<void(std::function<void()>)> submit;
  /// Pairs running or queued at once for this batch (>= 1), so that batches
  /// sharing one pool share it fairly. A fixed plan keeps one more queued,
  /// so a worker never idles while the pipeline stores the previous pair.
  int max_in_flight = 1;
  /// Polled between ICP evaluations and between pairs; true -> Cancelled.
  /// Empty = never.
  std::function<bool()> stop_requested;
};

struct RegisteredPairs {
  std::map<PairIndex, PairResult> finished;  // every finished pair the plan uses or probed
  std::vector<PairIndex> chain;              // the chain the poses are built from
  std::vector<PairIndex> bridges;            // pairs over doubtful chain pairs, in the order tried
  std::vector<PairIndex> loops;              // loop candidates registered, in the order found
  int reused = 0;                            // of `finished`, those loaded from the store
};

/// Loads the store's finished pairs, then registers the rest of `plan` with
/// RegisterBatchPair on `execution`, each pair with `config` scaled by its
/// PairScaleStep in `scale` (a default BatchScale scales nothing), saving each result in `store`
/// before it reports it to `progress`. Keyframe probes are handed out one at a time as slots free
/// up; the plan's decisions depend only on the recorded overlaps (KeyframePlanner), so the chain
/// does not depend on the thread count.
///
/// Returns only once no task it launched is running. Throws Cancelled when
/// stop_requested fires, and otherwise the first pair's failure (after
/// PairFailed) or whatever `progress` or `store` threw.
/// Preconditions: `config` is the batch's final config (ApplyBatchSettings
/// done); every index of `plan` is within `scans`.
RegisteredPairs RegisterPlannedPairs(const std::vector<ScanSource>& scans,
                                     const BoIcpConfig& config, const BatchScale& scale,
                                     const PairingPlan& plan, PairStore& store,
                                     MapProgressSink& progress, const PairExecution& execution);

}  // namespace boicp
