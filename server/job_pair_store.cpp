#include "job_pair_store.hpp"

#include "pair_result_proto.hpp"

namespace boicp::server {

std::vector<FinishedPair> JobPairStore::LoadFinished() {
  std::vector<FinishedPair> finished;
  std::lock_guard<std::mutex> lock(mutex_);
  for (StoredPair& stored : store_.GetPairs(spec_.job_id)) {
    finished.push_back(FinishedFromProto(stored.result, stored.information));
    results_[finished.back().pair] = std::move(stored.result);
  }
  return finished;
}

void JobPairStore::Save(const PairIndex& pair, int listing_order, const BatchPairResult& result) {
  v1::PairResult proto = PairResultToProto(spec_, pair, result);
  store_.PutPair(spec_.job_id, listing_order, proto, result.registration.information);
  std::lock_guard<std::mutex> lock(mutex_);
  results_[pair] = std::move(proto);
}

void JobPairStore::MarkInGraph(const std::vector<PairIndex>& in_graph) {
  store_.MarkPairsInGraph(spec_.job_id, in_graph);
}

std::optional<v1::PairResult> JobPairStore::Result(const PairIndex& pair) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = results_.find(pair);
  if (found == results_.end()) return std::nullopt;
  return found->second;
}

}  // namespace boicp::server
