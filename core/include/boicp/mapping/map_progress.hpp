#pragma once
// Where the map pipeline reports its progress: the daemon's watch events, or
// the terminal bar and plain lines of `boicp map`. Every call comes from the
// thread that runs the pipeline, never from a worker.

#include <string>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/map_stage.hpp"
#include "boicp/mapping/pair_result.hpp"

namespace boicp {

struct PairCounts {
  int done = 0;      // finished pairs, reused ones included
  int total = 0;     // pairs the plan holds so far (a keyframe plan grows as it goes)
  int doubtful = 0;  // of the finished ones
};

class MapProgressSink {
 public:
  virtual ~MapProgressSink() = default;

  /// The stored results are loaded; registration starts.
  virtual void RegistrationStarted(const PairCounts& /*counts*/) {}

  /// A pair is finished and stored. `reused`: it came from the store
  /// (reported before registration starts), not from this run.
  virtual void PairFinished(const PairResult& /*pair*/, bool /*reused*/,
                            const PairCounts& /*counts*/) {}

  /// A pair's registration or storage failed with `message`; the pipeline
  /// stops the other pairs and then rethrows the failure.
  virtual void PairFailed(const PairIndex& /*pair*/, const std::string& /*message*/) {}

  /// Called several times a second while pairs run (to refresh an ETA).
  virtual void Heartbeat() {}

  /// An assembly stage begins: kChaining or kOptimising (one step), then
  /// kFusing (`total` scans).
  virtual void StageStarted(MapStage /*stage*/, int /*total*/) {}

  /// The poses are estimated; `in_graph` are the pairs they use. Fusion follows.
  virtual void PosesEstimated(const PoseEstimate& /*estimate*/,
                              const std::vector<PairIndex>& /*in_graph*/) {}

  /// FuseScans' own progress (kFusing per scan, then kWriting).
  virtual void AssemblyStep(const AssemblyProgress& /*progress*/) {}
};

}  // namespace boicp
