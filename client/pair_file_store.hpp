#pragma once
// The map pipeline's pair store for `boicp map` and its shards: one JSON
// file per pair in OUTDIR/pairs (local_pairs.hpp), written atomically as
// each pair finishes. A file is reused only when its settings match the
// run's exactly; anything else is registered again and overwritten.

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
  std::vector<PairResult> LoadFinished() override;
  void Save(int listing_order, const PairResult& result) override;
  void MarkInGraph(const std::vector<PairIndex>& in_graph,
                   const std::map<PairIndex, std::string>& left_out) override;

 private:
  const std::vector<ScanSource>& scans_;
  const BoIcpConfig& config_;
  const std::string out_dir_;
};

}  // namespace boicp::cli
