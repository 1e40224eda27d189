#pragma once
// Progress of a local map run on stderr: a redrawn bar on a terminal, one
// line per pair otherwise, then the fusion stage.

#include "boicp/mapping/map_progress.hpp"

namespace boicp::cli {

/// The registration stage's counter and ETA.
class PairProgress {
 public:
  explicit PairProgress(int total);
  void SetTotal(int total);
  /// A pair finished (reused: its file was already there).
  void Done(const PairResult& result, bool reused);
  void Finish();

 private:
  int total_;
  int done_ = 0, registered_ = 0;
  double started_;
  double registering_s_ = 0.0;
  bool terminal_;
};

/// The map pipeline's progress sink for `boicp map`, `--shard` and `merge`.
class TerminalProgress : public MapProgressSink {
 public:
  TerminalProgress() : pairs_(0) {}

  void PairFinished(const PairResult& pair, bool reused, const PairCounts& counts) override;
  void StageStarted(MapStage stage, int total) override;
  void AssemblyStep(const AssemblyProgress& progress) override;

  /// Prints the registration summary line, once.
  void FinishPairs();

 private:
  PairProgress pairs_;
  bool reported_ = false;  // a pair was reported
  bool pairs_finished_ = false;
  bool terminal_ = false;
};

}  // namespace boicp::cli
