#include "job_manager.hpp"

#include <algorithm>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "job_spec.hpp"
#include "log_text.hpp"
#include "service_error.hpp"
#include "storage_check.hpp"

namespace boicp::server {
namespace {

namespace fs = std::filesystem;

// Runs of one job the daemon may die in before the job is failed instead of resumed.
constexpr int kMaxUnendedRuns = 2;

}  // namespace

JobManager::JobManager(JobStore& store, DataDir& data_dir, JobEventSink& events,
                       const ManagerOptions& options)
    : store_(store), data_dir_(data_dir), events_(events), options_(options) {
  pool_ = std::make_unique<ThreadPool>(options_.workers);
  context_ = std::make_unique<RunnerContext>(RunnerContext{
      store_, data_dir_, *pool_, events_, options_.registration_threads, options_.workers,
      options_.max_fusion_bytes, options_.max_job_seconds, options_.decode_budget});
}

JobManager::~JobManager() { Drain(); }

void JobManager::Start() {
  std::lock_guard<std::mutex> lock(mutex_);
  RemoveOrphanJobDirs();
  for (v1::Job& job : store_.UnfinishedJobs()) {
    if (job.cancel_requested()) {
      // Cancelled while a previous daemon ran it: finish the cancellation.
      job.set_state(v1::JOB_STATE_CANCELLED);
      rpc::SetJobStage(job, v1::JOB_STAGE_CANCELLED);
      job.set_finished_at(rpc::NowSeconds());
      store_.UpdateJob(job);
      Publish(job);
      spdlog::info("job {} cancelled (requested before the restart)", job.job_id());
      continue;
    }
    if (store_.UnendedRuns(job.job_id()) >= kMaxUnendedRuns) {
      // Resuming it again would most likely take this daemon down as well.
      job.set_state(v1::JOB_STATE_FAILED);
      rpc::SetJobStage(job, v1::JOB_STAGE_FAILED);
      job.set_error(
          "boicpd stopped unexpectedly (killed, perhaps for memory) in each of its last " +
          std::to_string(kMaxUnendedRuns) + " runs of this job; it is not resumed again");
      job.set_finished_at(rpc::NowSeconds());
      job.set_eta_seconds(-1.0);
      store_.UpdateJob(job);
      Publish(job);
      spdlog::error("job {} failed: {}", job.job_id(), job.error());
      continue;
    }
    spdlog::info("job {} resumes: {} of {} pairs done before the restart", job.job_id(),
                 job.pairs_done(), job.pairs_total());
    queue_.push_back(job.job_id());
    Publish(job);
  }
  accepting_ = true;
  for (int i = 0; i < std::max(options_.concurrent_jobs, 1); ++i) {
    slots_.emplace_back([this] { RunSlot(); });
  }
  housekeeping_ = std::thread([this] { RunHousekeeping(); });
}

v1::Job JobManager::Submit(const v1::SubmitBatchRequest& request) {
  if (request.scan_ids_size() > options_.max_batch_scans) {
    throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                       "scan_ids: " + std::to_string(request.scan_ids_size()) +
                           " scans is over this daemon's limit of " +
                           std::to_string(options_.max_batch_scans) + " (--max-batch-scans)");
  }
  JobInput input;
  input.request = request;
  std::vector<RangeProfile> profiles;
  for (int i = 0; i < request.scan_ids_size(); ++i) {
    const std::optional<StoredScan> scan = store_.GetScan(request.scan_ids(i));
    if (!scan || !data_dir_.HasScanFile(request.scan_ids(i))) {
      throw InputError("scan_ids[" + std::to_string(i) + "]: unknown scan id '" +
                       request.scan_ids(i) + "' (upload it first)");
    }
    // Scans stored under a higher limit, before a restart, meet the current one here.
    if (scan->num_points > options_.max_scan_points) {
      throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                         "scan_ids[" + std::to_string(i) +
                             "]: " + std::to_string(scan->num_points) +
                             " points is over this daemon's limit of " +
                             std::to_string(options_.max_scan_points) + " (--max-scan-points)");
    }
    input.scans.push_back(scan->metadata);
    profiles.push_back(scan->ranges);
  }
  const JobSpec spec =
      BuildJobSpec("new", request, input.scans, data_dir_, options_.registration_threads);
  const MapBatch& batch = spec.batch;
  RequireVoxelsFitExtent(batch.config, ProfilesExtent(profiles));
  // Map settings chosen from the scans are checked when the job starts.
  if (!batch.map_auto.resolution && !batch.map_auto.max_range) {
    RequireFusionWithinLimit(batch.scans, profiles, batch.map.occupancy, options_.max_fusion_bytes);
  }
  RequireStorage(data_dir_, options_.min_free_bytes);

  std::lock_guard<std::mutex> lock(mutex_);
  if (!accepting_) {
    throw ServiceError(grpc::StatusCode::UNAVAILABLE, "boicpd is shutting down");
  }
  // Unused scans are collected under this lock, so the batch's scans found
  // above are checked again here, then stay in use.
  for (int i = 0; i < request.scan_ids_size(); ++i) {
    if (!data_dir_.HasScanFile(request.scan_ids(i))) {
      throw InputError("scan_ids[" + std::to_string(i) + "]: scan '" + request.scan_ids(i) +
                       "' was deleted, unused, meanwhile (upload it again)");
    }
  }
  RequireStoredQuota(data_dir_, options_.max_stored_bytes);
  if (static_cast<int>(queue_.size()) >= options_.max_queued_jobs) {
    throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                       "the queue is full: " + std::to_string(queue_.size()) +
                           " jobs wait (--max-queued-jobs " +
                           std::to_string(options_.max_queued_jobs) + ")");
  }
  v1::Job job;
  job.set_label(request.label());
  job.set_state(v1::JOB_STATE_QUEUED);
  rpc::SetJobStage(job, v1::JOB_STAGE_QUEUED);
  job.set_num_scans(static_cast<uint32_t>(request.scan_ids_size()));
  job.set_drives(static_cast<uint32_t>(request.pairing().drive_starts_size() + 1));
  // A keyframe plan registers at least one pair per scan after the first.
  const size_t planned = (batch.plan.keyframes ? batch.scans.size() - 1 : batch.plan.chain.size()) +
                         batch.plan.extras.size();
  job.set_pairs_total(static_cast<uint32_t>(planned));
  job.set_eta_seconds(-1.0);
  job.set_created_at(rpc::NowSeconds());
  job = store_.CreateJob(job, input);
  queue_.push_back(job.job_id());
  queue_changed_.notify_one();
  Publish(job);
  spdlog::info("job {} queued: {} scans, {} pairs planned, preset {}, label '{}'", job.job_id(),
               job.num_scans(), job.pairs_total(), batch.config.preset, EscapeForLog(job.label()));
  return job;
}

v1::Job JobManager::Cancel(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<v1::Job> job = store_.GetJob(job_id);
  if (!job) throw ServiceError(grpc::StatusCode::NOT_FOUND, "no job '" + job_id + "'");
  if (const auto queued = std::find(queue_.begin(), queue_.end(), job_id); queued != queue_.end()) {
    queue_.erase(queued);
    job->set_state(v1::JOB_STATE_CANCELLED);
    rpc::SetJobStage(*job, v1::JOB_STAGE_CANCELLED);
    job->set_cancel_requested(true);
    job->set_finished_at(rpc::NowSeconds());
    job->set_eta_seconds(-1.0);
    store_.UpdateJob(*job);
    Publish(*job);
    spdlog::info("job {} cancelled while queued", job_id);
    return *job;
  }
  if (const auto running = running_.find(job_id); running != running_.end()) {
    running->second->Cancel();
    // Stored so that a daemon killed before the job stops still cancels it;
    // a job that finished meanwhile keeps its final state.
    job = store_.RequestCancel(job_id);
    spdlog::info("job {} cancel requested", job_id);
  }
  return *job;
}

v1::DeleteJobResponse JobManager::Delete(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::optional<v1::Job> job = store_.DeleteFinishedJob(job_id);
  if (!job) throw ServiceError(grpc::StatusCode::NOT_FOUND, "no job '" + job_id + "'");
  if (!rpc::IsTerminal(job->state())) {
    throw ServiceError(grpc::StatusCode::FAILED_PRECONDITION,
                       "job " + job_id + " is " + rpc::JobStateName(job->state()) +
                           "; cancel it first (boicp cancel " + job_id + ")");
  }
  v1::DeleteJobResponse response;
  response.set_job_id(job_id);
  response.set_bytes_freed(data_dir_.RemoveJobDir(job_id));
  spdlog::info("job {} deleted: {} bytes of outputs freed", job_id, response.bytes_freed());
  CollectUnusedScans();
  return response;
}

void JobManager::RunHousekeeping() {
  // A quarter of the shorter period between sweeps, so that a job or scan
  // outlives its time by at most a quarter; at least a second, at most an hour.
  double period = options_.scan_grace_seconds;
  if (options_.retain_seconds > 0.0) period = std::min(period, options_.retain_seconds);
  const auto interval = std::chrono::duration<double>(std::clamp(period / 4.0, 1.0, 3600.0));
  std::unique_lock<std::mutex> lock(mutex_);
  while (!draining_started_.wait_for(lock, interval, [this] { return draining_; })) {
    lock.unlock();
    if (options_.retain_seconds > 0.0) {
      const double cutoff = rpc::NowSeconds() - options_.retain_seconds;
      for (const std::string& job_id : store_.JobsFinishedBefore(cutoff)) {
        try {
          Delete(job_id);
        } catch (const std::exception& e) {
          spdlog::warn("job {}: past its retention but not deleted: {}", job_id, e.what());
        }
      }
    }
    lock.lock();
    try {
      CollectUnusedScans();
    } catch (const std::exception& e) {
      spdlog::warn("unused scans not collected: {}", e.what());
    }
  }
}

void JobManager::CollectUnusedScans() {
  const auto cutoff = fs::file_time_type::clock::now() -
                      std::chrono::duration_cast<fs::file_time_type::duration>(
                          std::chrono::duration<double>(options_.scan_grace_seconds));
  const std::vector<std::string> unused = data_dir_.ScansUnusedSince(cutoff);
  if (unused.empty()) return;
  const std::set<std::string> in_use = store_.ScansInUse();
  uint64_t bytes = 0;
  size_t count = 0;
  for (const std::string& scan_id : unused) {
    if (in_use.count(scan_id) != 0) continue;
    store_.DeleteScan(scan_id);
    bytes += data_dir_.RemoveScanFile(scan_id);
    ++count;
  }
  if (count > 0) spdlog::info("{} scans no job uses deleted: {} bytes freed", count, bytes);
}

void JobManager::RemoveOrphanJobDirs() {
  const std::set<std::string> jobs = store_.JobIds();
  for (const std::string& name : data_dir_.JobDirNames()) {
    if (jobs.count(name) != 0) continue;
    const uint64_t bytes = data_dir_.RemoveJobDir(name);
    spdlog::info(
        "removed jobs/{} ({} bytes): no job has it (a deletion the last daemon did not "
        "finish)",
        name, bytes);
  }
}

bool JobManager::Drain(std::chrono::milliseconds timeout) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    accepting_ = false;
    if (!draining_) {
      draining_ = true;
      for (auto& [id, control] : running_) control->Interrupt();
    }
    queue_changed_.notify_all();
    draining_started_.notify_all();
    const auto stopped = [this] { return running_.empty(); };
    if (timeout == std::chrono::milliseconds::max()) {
      job_ended_.wait(lock, stopped);
    } else if (!job_ended_.wait_for(lock, timeout, stopped)) {
      return false;
    }
  }
  for (std::thread& slot : slots_) slot.join();
  slots_.clear();
  if (housekeeping_.joinable()) housekeeping_.join();
  pool_.reset();  // every task has returned: each runner waited for its own
  return true;
}

void JobManager::RunSlot() {
  for (;;) {
    std::string job_id;
    std::shared_ptr<JobControl> control;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      queue_changed_.wait(lock, [this] { return draining_ || !queue_.empty(); });
      if (draining_) return;
      job_id = queue_.front();
      queue_.pop_front();
      control = std::make_shared<JobControl>();
      running_[job_id] = control;
    }
    std::optional<v1::Job> job;
    try {
      job = store_.GetJob(job_id);
    } catch (const std::exception& e) {
      spdlog::error("job {}: cannot read it from the data store: {}", job_id, e.what());
    }
    if (job) RunTracked(*job, *control);
    data_dir_.RecountJobDir(job_id);
    std::lock_guard<std::mutex> lock(mutex_);
    running_.erase(job_id);
    job_ended_.notify_all();
  }
}

// The store counts the run from its start to its end, so a run the daemon
// died in stays counted for the next start.
void JobManager::RunTracked(const v1::Job& job, JobControl& control) {
  try {
    store_.BeginRun(job.job_id());
  } catch (const std::exception& e) {
    spdlog::error("job {}: cannot record its run: {}", job.job_id(), e.what());
  }
  RunJob(*context_, control, job);
  try {
    store_.EndRun(job.job_id());
  } catch (const std::exception& e) {
    spdlog::error("job {}: cannot record the end of its run: {}", job.job_id(), e.what());
  }
}

void JobManager::Publish(const v1::Job& job) {
  v1::JobEvent event;
  *event.mutable_job() = job;
  events_.Publish(event);
}

}  // namespace boicp::server
