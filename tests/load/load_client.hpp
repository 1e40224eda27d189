#pragma once
// One load client: its own channel; uploads a batch of new scans, checks the
// daemon holds them, submits, then polls the job (GetJob, health, ListJobs)
// until it ends, timing every call; repeats until its window closes.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "batch_scans.hpp"
#include "load_options.hpp"
#include "rpc_stats.hpp"

namespace boicp::load {

using Clock = std::chrono::steady_clock;

struct ClientTotals {
  int jobs_submitted = 0;
  int jobs_succeeded = 0;
  int jobs_failed = 0;       // FAILED or CANCELLED (nobody cancels), or results missing
  int jobs_unfinished = 0;   // still open at the give-up time, or lost to an RPC error
  int submits_rejected = 0;  // RESOURCE_EXHAUSTED (queue full), retried after a pause
  int uploads = 0;
  int uploads_already_present = 0;
  uint64_t upload_bytes = 0;
  uint64_t pairs_completed = 0;
  std::vector<std::string> job_failures;  // "job_id: error"
  RpcStats rpc;

  void Merge(const ClientTotals& other);
};

struct ClientPlan {
  std::string address;             // HOST:PORT of the daemon
  int index = 0;                   // names the client in job labels
  uint64_t seed = 0;               // the client's own seed; each batch mixes in its number
  Clock::time_point submit_until;  // no batch starts after this
  Clock::time_point give_up_at;    // a job still open then counts as unfinished
};

/// Runs one client to the end of its plan. Never throws: RPC errors are
/// counted in the totals, and the first one ends the client (its open job
/// then counts as unfinished).
ClientTotals RunLoadClient(const ClientPlan& plan, const LoadOptions& options,
                           const BatchScans& scans);

}  // namespace boicp::load
