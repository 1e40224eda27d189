#pragma once
// Runs one job through core's map pipeline: its pair registrations on the
// shared pool (skipping pairs a previous run of the daemon finished), then
// map assembly on the calling thread. Every finished pair is stored before
// it is reported, so a daemon killed at any point resumes with only the
// unfinished pairs.

#include <atomic>
#include <chrono>
#include <cstddef>

#include "boicp/io/decode_budget.hpp"
#include "boicp/util/thread_pool.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "data_dir.hpp"
#include "job_events.hpp"
#include "job_store.hpp"

namespace boicp::server {

struct RunnerContext {
  JobStore& store;
  DataDir& data_dir;
  ThreadPool& pool;
  JobEventSink& events;
  int registration_threads = 1;
  int max_pairs_in_flight = 1;            // per job, so concurrent jobs share the pool
  size_t max_fusion_bytes = 0;            // one job's fusion memory; 0 = no limit
  double max_job_seconds = 0.0;           // from the job's first start; 0 = no deadline
  DecodeBudget* decode_budget = nullptr;  // every scan the job decodes; null = no budget
};

/// Stop requests for a running job, shared by the manager, the runner and
/// the job's pair tasks (which poll it between ICP evaluations; the pipeline
/// polls it between pairs, so a stop takes effect within one evaluation).
class JobControl {
 public:
  /// The user cancelled: the job ends CANCELLED.
  void Cancel();
  /// The daemon drains: the job stops but stays resumable.
  void Interrupt();
  /// The job stops, to fail, once the steady clock passes `deadline`. Set
  /// before the job's tasks start.
  void SetDeadline(std::chrono::steady_clock::time_point deadline);
  bool cancelled() const { return cancelled_; }
  bool interrupted() const { return interrupted_; }
  bool past_deadline() const;
  bool StopRequested() const { return cancelled_ || interrupted_ || past_deadline(); }

 private:
  std::atomic<bool> cancelled_{false};
  std::atomic<bool> interrupted_{false};
  std::chrono::steady_clock::time_point deadline_ = std::chrono::steady_clock::time_point::max();
};

enum class RunOutcome { kSucceeded, kFailed, kCancelled, kInterrupted };

/// Runs or resumes `job` until it succeeds, fails or is cancelled (recorded
/// in the store and published), or until an interrupt, which leaves it
/// RUNNING in the store for the next daemon to resume. Never throws.
RunOutcome RunJob(const RunnerContext& context, JobControl& control, ::boicp::v1::Job job);

}  // namespace boicp::server
