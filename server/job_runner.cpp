#include "job_runner.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include <spdlog/spdlog.h>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/map_assembly.hpp"
#include "job_outputs.hpp"
#include "job_spec.hpp"
#include "pair_task.hpp"
#include "proto_convert.hpp"
#include "scan_integrity.hpp"

namespace boicp::server {

void JobControl::Cancel() {
  std::lock_guard<std::mutex> lock(mutex);
  cancelled_ = true;
  changed.notify_all();
}

void JobControl::Interrupt() {
  std::lock_guard<std::mutex> lock(mutex);
  interrupted_ = true;
  changed.notify_all();
}

namespace {

namespace v1 = ::boicp::v1;
using Clock = std::chrono::steady_clock;

constexpr auto kProgressInterval = std::chrono::seconds(1);

PairIndex IndexOf(const v1::PairResult& result) {
  return {static_cast<int>(result.source()), static_cast<int>(result.target())};
}

// The keyframe planner's overlap estimate; results stored before overlap
// was computed fall back to their fitness.
double PlannerOverlap(const v1::PairResult& result) {
  return result.has_overlap() ? result.overlap() : result.fitness();
}

// The pose-graph weight of a stored pair; results stored before confidence
// was calibrated (no doubtful mark) are trusted, as they were then.
double EdgeConfidence(const v1::PairResult& result) {
  return result.has_doubtful() ? result.confidence() : 1.0;
}

std::pair<int, int> Unordered(const PairIndex& p) {
  return {std::min(p.source, p.target), std::max(p.source, p.target)};
}

// What a pair task hands back to the runner thread.
struct Completion {
  PairIndex pair;
  std::optional<StoredPair> stored;  // set on success
  bool stopped = false;              // Cancelled by a stop request
  std::string error;                 // set on failure
};

class JobRun {
 public:
  JobRun(const RunnerContext& context, JobControl& control, v1::Job job)
      : ctx_(context), control_(control), job_(std::move(job)) {}
  // Pair tasks refer to this run and to `control_`, which the caller frees
  // once the run returns.
  ~JobRun() { StopTasks(); }
  JobRun(const JobRun&) = delete;
  JobRun& operator=(const JobRun&) = delete;

  RunOutcome Run() {
    try {
      Prepare();
      if (!RegisterPairs()) return EndAfterStop();
      if (!failure_.empty()) return End(v1::JOB_STATE_FAILED, failure_);
      return Assemble();
    } catch (const Cancelled&) {
      StopTasks();
      return EndAfterStop();
    } catch (const std::exception& e) {
      StopTasks();  // no pair may be stored after the job's final state
      return End(v1::JOB_STATE_FAILED, e.what());
    }
  }

 private:
  // ---- Setup -----------------------------------------------------------
  void Prepare() {
    const std::optional<JobInput> input = ctx_.store.GetJobInput(job_.job_id());
    if (!input) throw std::runtime_error("the job's input is missing from the data store");
    spec_ = BuildJobSpec(job_.job_id(), input->request, input->scans, ctx_.data_dir,
                         ctx_.registration_threads);
    num_scans_ = static_cast<int>(spec_.scans.size());
    VerifyScans();
    // Chosen once from the job's scans; a resumed job chooses the same again.
    const std::vector<std::string> auto_fields =
        ApplyBatchSettings(spec_.scans, spec_.config, spec_.map.occupancy, spec_.map_auto);
    *job_.mutable_settings() = ChosenSettingsToProto(spec_.config, spec_.map, auto_fields);
    for (StoredPair& stored : ctx_.store.GetPairs(job_.job_id())) {
      results_[IndexOf(stored.result)] = std::move(stored);
    }
    if (spec_.pairing == PairingMode::kKeyframes) {
      planner_.emplace(num_scans_, spec_.overlap_threshold);
      for (const auto& [pair, stored] : results_) {
        planner_->Record(pair, PlannerOverlap(stored.result));
        probed_sources_.insert(pair.source);
      }
    } else {
      fixed_plan_ = spec_.base_pairs;
      fixed_plan_.insert(fixed_plan_.end(), spec_.extra_pairs.begin(), spec_.extra_pairs.end());
      for (const PairIndex& pair : fixed_plan_) {
        if (results_.count(pair) == 0) queue_.push_back(pair);
      }
    }
    for (const PairIndex& pair : spec_.extra_pairs) {
      if (spec_.pairing == PairingMode::kKeyframes && results_.count(pair) == 0) {
        extras_queue_.push_back(pair);
      }
    }
    // Listing order: a fixed plan's own order; keyframe pairs in launch order.
    for (size_t i = 0; i < fixed_plan_.size(); ++i) {
      plan_order_[fixed_plan_[i]] = static_cast<int>(i);
    }
    next_order_ = static_cast<int>(results_.size());

    const int resumed = static_cast<int>(results_.size());
    job_.set_state(v1::JOB_STATE_RUNNING);
    if (job_.started_at() == 0.0) job_.set_started_at(NowSeconds());
    job_.set_stage("registering");
    job_.set_eta_seconds(-1.0);
    UpdateCounts();
    Persist();
    Publish(nullptr);
    spdlog::info("job {} running: {} scans, {} pairing, preset {}, {} of {} pairs already done",
                 job_.job_id(), num_scans_, PairingName(), spec_.config.preset, resumed,
                 job_.pairs_total());
  }

  // A scan whose bytes no longer match its name fails the job (the error
  // names it) rather than feeding a wrong cloud into the map.
  void VerifyScans() const {
    const std::set<std::string> unique(spec_.scan_ids.begin(), spec_.scan_ids.end());
    for (const std::string& scan_id : unique) VerifyStoredScan(ctx_.data_dir, scan_id);
  }

  std::string PairingName() const {
    switch (spec_.pairing) {
      case PairingMode::kConsecutive:
        return "consecutive";
      case PairingMode::kKeyframes:
        return "keyframe";
      case PairingMode::kExplicit:
        return "explicit";
    }
    return "unknown";
  }

  // Asks the running pair tasks to stop and waits until none is left.
  void StopTasks() {
    aborting_ = true;
    std::unique_lock<std::mutex> lock(control_.mutex);
    control_.changed.wait(lock, [this] { return in_flight_ == 0; });
  }

  // ---- Registration stage ------------------------------------------------
  // Returns false when a stop request ended it.
  bool RegisterPairs() {
    run_start_ = Clock::now();
    last_progress_ = run_start_;
    std::unique_lock<std::mutex> lock(control_.mutex);
    bool stop_seen = false;
    for (;;) {
      if (!control_.StopRequested() && failure_.empty()) {
        lock.unlock();
        LaunchAvailable();
        lock.lock();
      }
      // A pair may have finished while the previous batch was absorbed: its
      // completion waits in completions_ and must be absorbed before the end.
      if (in_flight_ == 0 && completions_.empty() &&
          (PlanComplete() || control_.StopRequested() || !failure_.empty())) {
        break;
      }
      control_.changed.wait_for(lock, kProgressInterval, [&] {
        return !completions_.empty() || (control_.StopRequested() && !stop_seen);
      });
      if (control_.StopRequested() && !stop_seen) {
        stop_seen = true;
        job_.set_cancel_requested(control_.cancelled());
      }
      std::deque<Completion> batch;
      batch.swap(completions_);
      lock.unlock();
      for (Completion& completion : batch) Absorb(std::move(completion));
      MaybePublishProgress();
      lock.lock();
    }
    return !control_.StopRequested();
  }

  bool PlanComplete() const {
    if (planner_) return planner_->Done() && extras_queue_.empty();
    return queue_.empty();
  }

  // Hands pairs to the pool until the job's share of it is used. A fixed plan
  // keeps one more pair waiting in the pool, so a worker that finishes a pair
  // starts the next at once instead of idling while this thread stores the
  // last one. Keyframe probes wait: the next probe depends on the results.
  void LaunchAvailable() {
    const int limit = ctx_.max_pairs_in_flight + (planner_ ? 0 : 1);
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(control_.mutex);
        if (in_flight_ >= limit) return;
      }
      const std::optional<PairIndex> next = NextPair();
      if (!next) return;
      Launch(*next);
    }
  }

  std::optional<PairIndex> NextPair() {
    if (!planner_) {
      if (queue_.empty()) return std::nullopt;
      const PairIndex pair = queue_.front();
      queue_.pop_front();
      return pair;
    }
    for (const PairIndex& probe : planner_->NextProbes(1)) {
      if (results_.count(probe) != 0 || launched_.count(probe) != 0) continue;
      probed_sources_.insert(probe.source);
      return probe;
    }
    if (!extras_queue_.empty()) {
      const PairIndex pair = extras_queue_.front();
      extras_queue_.pop_front();
      return pair;
    }
    return std::nullopt;
  }

  void Launch(const PairIndex& pair) {
    launched_.insert(pair);
    const auto planned = plan_order_.find(pair);
    const int order = planned != plan_order_.end() ? planned->second : next_order_++;
    {
      std::lock_guard<std::mutex> lock(control_.mutex);
      ++in_flight_;
    }
    // The runner waits for every launched task before it returns, so the
    // task may refer to it.
    ctx_.pool.Submit([this, pair, order, job_id = job_.job_id()] {
      Completion completion;
      completion.pair = pair;
      if (control_.StopRequested() || aborting_) {
        completion.stopped = true;
      } else {
        try {
          PairOutcome outcome = RegisterJobPair(
              spec_, pair, [this] { return control_.StopRequested() || aborting_; });
          ctx_.store.PutPair(job_id, order, outcome.result, outcome.information);
          completion.stored = StoredPair{std::move(outcome.result), outcome.information};
        } catch (const Cancelled&) {
          completion.stopped = true;
        } catch (const std::exception& e) {
          completion.error = e.what();
        }
      }
      std::lock_guard<std::mutex> lock(control_.mutex);
      --in_flight_;
      completions_.push_back(std::move(completion));
      control_.changed.notify_all();
    });
  }

  void Absorb(Completion completion) {
    launched_.erase(completion.pair);
    const std::string name =
        std::to_string(completion.pair.source) + "->" + std::to_string(completion.pair.target);
    if (!completion.error.empty()) {
      spdlog::error("job {} pair {} failed: {}", job_.job_id(), name, completion.error);
      if (failure_.empty()) failure_ = "pair " + name + ": " + completion.error;
      aborting_ = true;  // the job fails: the other pairs need not finish
      return;
    }
    if (!completion.stored) return;
    const v1::PairResult& r = completion.stored->result;
    results_[completion.pair] = *completion.stored;
    ++done_this_run_;
    last_done_ = Clock::now();
    if (planner_) planner_->Record(completion.pair, PlannerOverlap(r));
    UpdateCounts();
    Persist();
    spdlog::info(
        "job {} pair {} done in {:.2f} s ({}/{}): fitness {:.3f}, confidence {:.3f}{}, "
        "objective {:.4f} m",
        job_.job_id(), name, r.runtime_s(), job_.pairs_done(), job_.pairs_total(), r.fitness(),
        r.confidence(), r.doubtful() ? " (doubtful)" : "", r.objective());
    Publish(&r);
  }

  void UpdateCounts() {
    job_.set_pairs_done(static_cast<uint32_t>(results_.size()));
    job_.set_pairs_doubtful(static_cast<uint32_t>(
        std::count_if(results_.begin(), results_.end(),
                      [](const auto& entry) { return entry.second.result.doubtful(); })));
    if (planner_) {
      // Keyframe plans grow as they go: what ran or runs, plus one probe per
      // scan not probed yet.
      const int unprobed = std::max(0, num_scans_ - 1 - static_cast<int>(probed_sources_.size()));
      job_.set_pairs_total(
          static_cast<uint32_t>(results_.size() + launched_.size() + extras_queue_.size()) +
          static_cast<uint32_t>(unprobed));
    } else {
      job_.set_pairs_total(static_cast<uint32_t>(fixed_plan_.size()));
    }
    job_.set_stage_done(job_.pairs_done());
    job_.set_stage_total(job_.pairs_total());
    UpdateEta();
  }

  // Pairs finish at the rate seen so far in this run; the ETA counts down
  // between completions.
  void UpdateEta() {
    if (done_this_run_ == 0 || job_.stage() != "registering") return;
    const double per_pair =
        std::chrono::duration<double>(last_done_ - run_start_).count() / done_this_run_;
    const double remaining =
        static_cast<double>(job_.pairs_total()) - static_cast<double>(job_.pairs_done());
    const double since = std::chrono::duration<double>(Clock::now() - last_done_).count();
    job_.set_eta_seconds(std::max(per_pair * std::max(remaining, 0.0) - since, 0.0));
  }

  void MaybePublishProgress() {
    if (Clock::now() - last_progress_ < kProgressInterval) return;
    UpdateEta();
    Publish(nullptr);
  }

  // ---- Assembly ----------------------------------------------------------
  RunOutcome Assemble() {
    std::vector<PairIndex> chain =
        planner_ ? planner_->ChainPairs() : std::vector<PairIndex>(spec_.base_pairs);
    std::set<std::pair<int, int>> in_chain;
    for (const PairIndex& p : chain) in_chain.insert(Unordered(p));
    std::vector<PairConstraint> constraints;
    std::vector<PairIndex> used;
    auto add = [&](const PairIndex& p) {
      const StoredPair& stored = results_.at(p);
      constraints.push_back({p, TransformFromProto(stored.result.transform(), "stored pair"),
                             stored.information, EdgeConfidence(stored.result)});
      used.push_back(p);
    };
    for (const PairIndex& p : chain) add(p);
    // Loop closures; a keyframe chain may already hold the same two scans.
    for (const PairIndex& p : spec_.extra_pairs) {
      if (in_chain.count(Unordered(p)) == 0) add(p);
    }

    const bool loops = static_cast<int>(constraints.size()) > num_scans_ - 1;
    SetStage(loops ? "optimising" : "chaining", 0, 1);
    const PoseEstimate estimate =
        EstimatePoses(spec_.scans, constraints, BatchPoseGraphOptions(spec_.config));
    std::vector<PairIndex> kept;
    for (size_t i = 0; i < used.size(); ++i) {
      if (estimate.kept[i]) kept.push_back(used[i]);
    }
    ctx_.store.MarkPairsInGraph(job_.job_id(), kept);
    job_.set_pose_graph_optimised(estimate.optimised);
    if (estimate.optimised) {
      spdlog::info("job {} pose graph optimised: {} loop closures, {} of {} edges kept",
                   job_.job_id(), estimate.loop_closures, kept.size(), used.size());
    }

    const std::string dir = ctx_.data_dir.CreateJobDir(job_.job_id());
    RemoveStagingFiles(dir);
    SetStage("fusing", 0, static_cast<uint32_t>(num_scans_));
    VerifyScans();  // fusion reads every scan again; the registrations took a while
    const auto fuse_start = Clock::now();
    AssemblyCallbacks callbacks;
    callbacks.stop_requested = [this] { return control_.StopRequested(); };
    callbacks.progress = [this, fuse_start](const AssemblyProgress& p) {
      const bool new_stage = p.stage != job_.stage();
      if (new_stage) job_.set_stage(p.stage);
      job_.set_stage_done(static_cast<uint32_t>(p.done));
      job_.set_stage_total(static_cast<uint32_t>(p.total));
      if (p.stage == "fusing" && p.done > 0) {
        const double elapsed = std::chrono::duration<double>(Clock::now() - fuse_start).count();
        job_.set_eta_seconds(elapsed / p.done * (p.total - p.done));
      }
      if (new_stage) {
        Publish(nullptr);  // watchers see "writing" begin, not a second later
      } else {
        MaybePublishProgress();
      }
    };
    spec_.map.fusion_threads = ctx_.pool.size();  // one per --workers: the pairs are done
    const FusionSummary summary =
        FuseScans(spec_.scans, estimate.poses, spec_.map, JobOutputPaths(dir), callbacks);
    RequireOutputsWritten(JobOutputPaths(dir));
    spdlog::info("job {} fused {} scans in {:.1f} s: {} occupied leaves, {} cloud points",
                 job_.job_id(), num_scans_, summary.seconds, summary.occupied_leaves,
                 summary.cloud_points);

    std::vector<v1::TrajectoryPose> trajectory;
    const std::vector<double> stamps = ScanTimestamps(spec_.scans);
    for (int i = 0; i < num_scans_; ++i) {
      v1::TrajectoryPose pose;
      pose.set_index(static_cast<uint32_t>(i));
      pose.set_scan_id(spec_.scan_ids[static_cast<size_t>(i)]);
      TransformToProto(estimate.poses[static_cast<size_t>(i)], pose.mutable_pose());
      pose.set_timestamp(stamps[static_cast<size_t>(i)]);
      trajectory.push_back(std::move(pose));
    }
    ctx_.store.PutTrajectory(job_.job_id(), trajectory);
    return End(v1::JOB_STATE_SUCCEEDED, "");
  }

  void SetStage(const std::string& stage, uint32_t done, uint32_t total) {
    job_.set_stage(stage);
    job_.set_stage_done(done);
    job_.set_stage_total(total);
    job_.set_eta_seconds(-1.0);
    Persist();
    Publish(nullptr);
  }

  // ---- Endings -------------------------------------------------------------
  RunOutcome EndAfterStop() {
    if (control_.cancelled()) return End(v1::JOB_STATE_CANCELLED, "");
    spdlog::info("job {} interrupted by shutdown after {} of {} pairs; it resumes on restart",
                 job_.job_id(), job_.pairs_done(), job_.pairs_total());
    return RunOutcome::kInterrupted;
  }

  RunOutcome End(v1::JobState state, const std::string& error) {
    job_.set_state(state);
    job_.set_stage(state == v1::JOB_STATE_SUCCEEDED ? "done" : JobStateName(state));
    job_.set_error(error);
    job_.set_finished_at(NowSeconds());
    job_.set_eta_seconds(state == v1::JOB_STATE_SUCCEEDED ? 0.0 : -1.0);
    job_.set_cancel_requested(control_.cancelled());
    // Watchers learn a final state only once it is stored: one that was not
    // stays RUNNING in the store, and the next daemon resumes the job.
    try {
      Persist();
    } catch (const std::exception& e) {
      spdlog::error("job {}: cannot record the final state {}: {}", job_.job_id(),
                    JobStateName(state), e.what());
      return RunOutcome::kFailed;
    }
    Publish(nullptr);
    const double took = job_.finished_at() - job_.started_at();
    if (state == v1::JOB_STATE_FAILED) {
      spdlog::error("job {} failed after {:.1f} s: {}", job_.job_id(), took, error);
      return RunOutcome::kFailed;
    }
    spdlog::info("job {} {} after {:.1f} s ({} of {} pairs; {})", job_.job_id(),
                 JobStateName(state), took, job_.pairs_done(), job_.pairs_total(),
                 DoubtfulSummary(static_cast<int>(job_.pairs_doubtful()),
                                 static_cast<int>(job_.pairs_done())));
    return state == v1::JOB_STATE_SUCCEEDED ? RunOutcome::kSucceeded : RunOutcome::kCancelled;
  }

  void Persist() {
    if (control_.cancelled()) job_.set_cancel_requested(true);
    if (!ctx_.store.UpdateJob(job_)) {
      throw std::runtime_error("the data store already holds a final state for this job");
    }
  }

  void Publish(const v1::PairResult* pair) {
    v1::JobEvent event;
    *event.mutable_job() = job_;
    if (pair) *event.mutable_pair() = *pair;
    ctx_.events.Publish(event);
    last_progress_ = Clock::now();
  }

  const RunnerContext& ctx_;
  JobControl& control_;
  v1::Job job_;
  JobSpec spec_;
  int num_scans_ = 0;
  std::map<PairIndex, StoredPair> results_;
  std::optional<KeyframePlanner> planner_;
  std::vector<PairIndex> fixed_plan_;
  std::deque<PairIndex> queue_;
  std::deque<PairIndex> extras_queue_;
  std::set<PairIndex> launched_;
  std::set<int> probed_sources_;
  std::map<PairIndex, int> plan_order_;
  int next_order_ = 0;
  std::atomic<bool> aborting_{false};
  int done_this_run_ = 0;
  std::string failure_;
  Clock::time_point run_start_;
  Clock::time_point last_progress_;
  Clock::time_point last_done_;  // when this run last finished a pair
  // Guarded by control_.mutex.
  int in_flight_ = 0;
  std::deque<Completion> completions_;
};

}  // namespace

RunOutcome RunJob(const RunnerContext& context, JobControl& control, ::boicp::v1::Job job) {
  JobRun run(context, control, std::move(job));
  return run.Run();
}

}  // namespace boicp::server
