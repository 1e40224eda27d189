#pragma once
// The map pipeline's pair store for a daemon job: the job's rows in the
// SQLite job store, each pair written in its own transaction.

#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "boicp/mapping/pair_store.hpp"
#include "job_spec.hpp"
#include "job_store.hpp"

namespace boicp::server {

class JobPairStore : public PairStore {
 public:
  /// `store` and `spec` must outlive this.
  JobPairStore(JobStore& store, const JobSpec& spec) : store_(store), spec_(spec) {}

  std::vector<PairResult> LoadFinished() override;
  void Save(int listing_order, const PairResult& result) override;
  void MarkInGraph(const std::vector<PairIndex>& in_graph,
                   const std::map<PairIndex, std::string>& left_out) override;

  /// The stored result of `pair` as the API reports it; nullopt when none is stored.
  std::optional<::boicp::v1::PairResult> Result(const PairIndex& pair) const;

 private:
  JobStore& store_;
  const JobSpec& spec_;
  mutable std::mutex mutex_;  // Save runs on worker threads
  std::map<PairIndex, ::boicp::v1::PairResult> results_;
};

}  // namespace boicp::server
