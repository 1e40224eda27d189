#pragma once
// The map pipeline's pair store for `boicp map` and its shards: one JSON
// file per pair in OUTDIR/pairs (local_pairs.hpp), written atomically as
// each pair finishes. A file is reused only when its settings match the
// run's exactly; anything else is registered again and overwritten.

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "boicp/mapping/pair_store.hpp"
#include "local_pairs.hpp"

namespace boicp::cli {

class PairFileStore : public PairStore {
 public:
  /// `scans` and `config` (the run's final settings) must outlive this.
  PairFileStore(const std::vector<ScanSource>& scans, const BoIcpConfig& config,
                std::string out_dir);

  /// Every readable file in OUTDIR/pairs whose pair lies within the scans
  /// and whose settings match the run's.
  std::vector<FinishedPair> LoadFinished() override;
  void Save(const PairIndex& pair, int listing_order, const BatchPairResult& result) override;
  void MarkInGraph(const std::vector<PairIndex>& in_graph) override;

  /// The record of a loaded or saved pair. Throws std::out_of_range for another.
  PairRecord Record(const PairIndex& pair) const;

 private:
  const std::vector<ScanSource>& scans_;
  const BoIcpConfig& config_;
  const std::string out_dir_;
  mutable std::mutex mutex_;  // Save runs on worker threads
  std::map<PairIndex, PairRecord> records_;
};

/// The pose-graph view of a record (RecordConstraint, PlannerOverlap, IsDoubtful).
FinishedPair FinishedFromRecord(const PairRecord& record);

}  // namespace boicp::cli
