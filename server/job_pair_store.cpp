#include "job_pair_store.hpp"

#include "boicp/rpc/pair_result_proto.hpp"
#include "boicp/rpc/proto_convert.hpp"

namespace boicp::server {

std::vector<PairResult> JobPairStore::LoadFinished() {
  std::vector<PairResult> finished;
  std::lock_guard<std::mutex> lock(mutex_);
  for (StoredPair& stored : store_.GetPairs(spec_.job_id)) {
    finished.push_back(rpc::PairResultFromProto(stored.result));
    finished.back().information = stored.information;
    results_[finished.back().pair] = std::move(stored.result);
  }
  return finished;
}

void JobPairStore::Save(int listing_order, const PairResult& result) {
  const PairIndex& pair = result.pair;
  PairResult finished = result;
  finished.finished_at = rpc::NowSeconds();
  v1::PairResult proto;
  rpc::PairResultToProto(finished, &proto);
  proto.set_source_scan_id(spec_.scan_ids.at(static_cast<size_t>(pair.source)));
  proto.set_target_scan_id(spec_.scan_ids.at(static_cast<size_t>(pair.target)));
  store_.PutPair(spec_.job_id, listing_order, proto, result.information);
  std::lock_guard<std::mutex> lock(mutex_);
  results_[pair] = std::move(proto);
}

void JobPairStore::MarkInGraph(const std::vector<PairIndex>& in_graph,
                               const std::map<PairIndex, std::string>& left_out) {
  store_.MarkPairsInGraph(spec_.job_id, in_graph, left_out);
}

std::optional<v1::PairResult> JobPairStore::Result(const PairIndex& pair) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = results_.find(pair);
  if (found == results_.end()) return std::nullopt;
  return found->second;
}

}  // namespace boicp::server
