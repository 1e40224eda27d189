#pragma once
// The job queue: accepts batches, runs up to `concurrent_jobs` of them at a
// time on job-slot threads (their pairs on one shared worker pool), cancels,
// resumes what a previous daemon left unfinished, and drains on shutdown.

#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "boicp/io/decode_budget.hpp"
#include "boicp/util/thread_pool.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "data_dir.hpp"
#include "job_events.hpp"
#include "job_runner.hpp"
#include "job_store.hpp"

namespace boicp::server {

namespace v1 = ::boicp::v1;

struct ManagerOptions {
  int workers = 1;                     // pool threads: pair registrations running at once
  int concurrent_jobs = 1;             // jobs running at once (each also fuses its map on its slot)
  int registration_threads = 1;        // threads inside one registration
  int max_queued_jobs = 64;            // queued (not yet running) jobs; more is RESOURCE_EXHAUSTED
  int max_batch_scans = 100000;        // scans per batch; more is RESOURCE_EXHAUSTED
  uint64_t max_scan_points = 5000000;  // points per stored scan; more is RESOURCE_EXHAUSTED
  uint64_t min_free_bytes = 0;  // below it (or unwritable) new batches are FAILED_PRECONDITION
  double retain_seconds = 0.0;  // finished jobs older than this are deleted; 0 = kept for good
  double scan_grace_seconds = 86400.0;    // scans no job uses go this long after their last use
  uint64_t max_stored_bytes = 0;          // scans and outputs; 0 = no cap
  size_t max_fusion_bytes = 0;            // one job's fusion memory; 0 = no limit
  double max_job_seconds = 0.0;           // a running job fails past it; 0 = no deadline
  DecodeBudget* decode_budget = nullptr;  // shared with the uploads; null = no budget
};

class JobManager {
 public:
  JobManager(JobStore& store, DataDir& data_dir, JobEventSink& events,
             const ManagerOptions& options);
  /// Drains if Drain() was not called.
  ~JobManager();
  JobManager(const JobManager&) = delete;
  JobManager& operator=(const JobManager&) = delete;

  /// Queues every job a previous daemon left queued or running, then starts
  /// the job slots.
  void Start();

  /// Validates and queues a batch; returns the queued job. Throws
  /// InputError (bad batch), ServiceError RESOURCE_EXHAUSTED (limits) or
  /// UNAVAILABLE (draining), LimitExceeded (a map estimated over the fusion
  /// memory limit), StorageError (data directory unwritable or below its
  /// reserve).
  v1::Job Submit(const v1::SubmitBatchRequest& request);

  /// Cancels a queued job at once, asks a running one to stop (its state
  /// turns CANCELLED within seconds), and leaves a finished one as it is.
  /// Throws ServiceError NOT_FOUND.
  v1::Job Cancel(const std::string& job_id);

  /// Deletes a succeeded, failed or cancelled job: its rows go in one
  /// transaction, then its output folder. A daemon killed in between leaves
  /// no job and a folder that Start() removes. Throws ServiceError NOT_FOUND,
  /// or FAILED_PRECONDITION while the job is queued or running.
  v1::DeleteJobResponse Delete(const std::string& job_id);

  /// Stops accepting, interrupts running jobs (finished pairs are already
  /// stored; they stay resumable) and joins every thread once they stopped.
  /// Returns false, with the jobs still stopping, when that takes longer
  /// than `timeout`. Idempotent.
  bool Drain(std::chrono::milliseconds timeout = std::chrono::milliseconds::max());

 private:
  /// Removes folders under jobs/ that no stored job owns.
  void RemoveOrphanJobDirs();
  /// Now and then until the manager drains: deletes the jobs that finished
  /// over options_.retain_seconds ago, and collects unused scans.
  void RunHousekeeping();
  /// Deletes the scans no job uses that were last used over
  /// options_.scan_grace_seconds ago. Call with mutex_ held, so that no
  /// batch takes a scan meanwhile.
  void CollectUnusedScans();
  void RunSlot();
  void RunTracked(const v1::Job& job, JobControl& control);
  void Publish(const v1::Job& job);

  JobStore& store_;
  DataDir& data_dir_;
  JobEventSink& events_;
  ManagerOptions options_;
  std::unique_ptr<ThreadPool> pool_;
  std::unique_ptr<RunnerContext> context_;

  std::mutex mutex_;
  std::condition_variable queue_changed_;
  std::condition_variable job_ended_;
  std::condition_variable draining_started_;  // wakes the housekeeping thread
  std::deque<std::string> queue_;
  std::map<std::string, std::shared_ptr<JobControl>> running_;
  bool accepting_ = false;
  bool draining_ = false;
  std::vector<std::thread> slots_;
  std::thread housekeeping_;
};

}  // namespace boicp::server
