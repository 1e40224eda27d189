#include "job_runner.hpp"

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>
#include <sstream>

#include <spdlog/spdlog.h>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/mapping/map_pipeline.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "job_outputs.hpp"
#include "job_pair_store.hpp"
#include "job_spec.hpp"
#include "scan_integrity.hpp"
#include "service_error.hpp"

namespace boicp::server {

void JobControl::Cancel() { cancelled_ = true; }

void JobControl::Interrupt() { interrupted_ = true; }

void JobControl::SetDeadline(std::chrono::steady_clock::time_point deadline) {
  deadline_ = deadline;
}

bool JobControl::past_deadline() const { return std::chrono::steady_clock::now() > deadline_; }

namespace {

namespace v1 = ::boicp::v1;
using Clock = std::chrono::steady_clock;

constexpr auto kProgressInterval = std::chrono::seconds(1);

// One run of a job: core's map pipeline with the job's rows in the job store
// as its pair store, and this class as its progress sink (the job record,
// persisted and published to watchers). What stays here is the job's
// lifetime: its state, its ETA, and how it ends.
class JobRun : public MapProgressSink {
 public:
  JobRun(const RunnerContext& context, JobControl& control, v1::Job job)
      : ctx_(context), control_(control), job_(std::move(job)) {}
  JobRun(const JobRun&) = delete;
  JobRun& operator=(const JobRun&) = delete;

  RunOutcome Run() {
    try {
      Prepare();
      JobPairStore pairs(ctx_.store, spec_);
      pairs_ = &pairs;
      PairExecution execution;
      execution.submit = [this](std::function<void()> task) { ctx_.pool.Submit(std::move(task)); };
      execution.max_in_flight = ctx_.max_pairs_in_flight;
      execution.stop_requested = [this] { return control_.StopRequested(); };
      // Returns only once none of the job's pair tasks runs: no pair is
      // stored after the job's final state, whatever was thrown.
      MapPipelineHooks hooks;
      hooks.before_fusion = [this] { PrepareFusion(); };
      const MapPipelineResult result =
          RunMapPipeline(spec_.batch, pairs, *this, execution,
                         JobOutputPaths(ctx_.data_dir.JobDir(job_.job_id())), hooks);
      pairs_ = nullptr;
      return Finish(result);
    } catch (const Cancelled&) {
      pairs_ = nullptr;
      return EndAfterStop();
    } catch (const std::exception& e) {
      pairs_ = nullptr;
      return End(v1::JOB_STATE_FAILED, failure_.empty() ? e.what() : failure_);
    }
  }

 private:
  // ---- Setup -----------------------------------------------------------
  void Prepare() {
    const std::optional<JobInput> input = ctx_.store.GetJobInput(job_.job_id());
    if (!input) throw std::runtime_error("the job's input is missing from the data store");
    spec_ = BuildJobSpec(job_.job_id(), input->request, input->scans, ctx_.data_dir,
                         ctx_.registration_threads);
    // Every load of the job's scans (settings, pairs, fusion) shares the
    // daemon's decode budget with the uploads, and stops waiting for it
    // when the job stops.
    for (ScanSource& scan : spec_.batch.scans) {
      scan.load.decode_budget = ctx_.decode_budget;
      scan.load.decode_stop = [this] { return control_.StopRequested(); };
    }
    VerifyScans();
    // Chosen once from the job's scans; a resumed job chooses the same again.
    const std::vector<RangeProfile> profiles = ScanProfiles();
    const BatchSettingsChoice choice = ChooseBatchSettings(spec_.batch, profiles);
    *job_.mutable_settings() = ChosenSettingsToProto(spec_.batch.config, spec_.batch.map, choice);
    job_.mutable_settings()->set_scan_format(
        rpc::ScanFormatOf(spec_.batch.scans.at(0).load.format));
    // Fusion starts once this job's pairs are done; its ray casting takes one
    // thread per worker (the map does not depend on the count).
    spec_.batch.map.fusion_threads = ctx_.pool.size();
    spec_.batch.map.max_fusion_bytes = ctx_.max_fusion_bytes;
    RequireFusionWithinLimit(spec_.batch.scans, profiles, spec_.batch.map.occupancy,
                             ctx_.max_fusion_bytes);
    job_.set_state(v1::JOB_STATE_RUNNING);
    if (job_.started_at() == 0.0) job_.set_started_at(rpc::NowSeconds());
    if (ctx_.max_job_seconds > 0.0) {
      // From the job's first start: a resumed job does not begin again.
      const double left = ctx_.max_job_seconds - (rpc::NowSeconds() - job_.started_at());
      control_.SetDeadline(Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(std::max(left, 0.0))));
    }
    rpc::SetJobStage(job_, rpc::JobStageOf(MapStage::kRegistering));
    job_.set_eta_seconds(-1.0);
  }

  // Each scan's range profile as stored at upload (empty for scans stored
  // before profiles were).
  std::vector<RangeProfile> ScanProfiles() const {
    std::vector<RangeProfile> profiles;
    for (const std::string& scan_id : spec_.scan_ids) {
      const std::optional<StoredScan> scan = ctx_.store.GetScan(scan_id);
      profiles.push_back(scan ? scan->ranges : RangeProfile{});
    }
    return profiles;
  }

  // A scan whose bytes no longer match its name fails the job (the error
  // names it) rather than feeding a wrong cloud into the map.
  void VerifyScans() const {
    const std::set<std::string> unique(spec_.scan_ids.begin(), spec_.scan_ids.end());
    for (const std::string& scan_id : unique) VerifyStoredScan(ctx_.data_dir, scan_id);
  }

  // ---- Progress (MapProgressSink) ------------------------------------------
  void RegistrationStarted(const PairCounts& counts) override {
    run_start_ = Clock::now();
    SetCounts(counts);
    Persist();
    Publish(nullptr);
    spdlog::info("job {} running: {} scans, {} pairing, preset {}, {} of {} pairs already done",
                 job_.job_id(), spec_.batch.scans.size(), PairingModeName(spec_.batch.pairing.mode),
                 spec_.batch.config.preset, counts.done, counts.total);
    if (const std::string rescaled = DescribeScansAtAnotherScale(spec_.batch.scale);
        !rescaled.empty()) {
      spdlog::info("job {}: {}", job_.job_id(), rescaled);
    }
  }

  void PairFinished(const PairResult& pair, bool reused, const PairCounts& counts) override {
    if (reused) return;  // counted by RegistrationStarted
    ++done_this_run_;
    last_done_ = Clock::now();
    SetCounts(counts);
    Persist();
    spdlog::info(
        "job {} pair {} done in {:.2f} s ({}/{}): fitness {:.3f}, confidence {:.3f}{}, "
        "objective {:.4f} m, answered by {} in {} evaluations",
        job_.job_id(), PairName(pair.pair), pair.runtime_s, job_.pairs_done(), job_.pairs_total(),
        pair.fitness, pair.confidence, pair.doubtful ? " (doubtful)" : "", pair.objective,
        RungName(pair.answered_by), pair.evaluations);
    // The stored message, with the scan ids and the time it was stored.
    const std::optional<v1::PairResult> stored = pairs_->Result(pair.pair);
    if (!stored) throw std::logic_error("a finished pair is missing from the job's pair store");
    Publish(&*stored);
  }

  void PairFailed(const PairIndex& pair, const std::string& message) override {
    spdlog::error("job {} pair {} failed: {}", job_.job_id(), PairName(pair), message);
    failure_ = "pair " + PairName(pair) + ": " + message;
  }

  void Heartbeat() override { MaybePublishProgress(); }

  void PosesEstimated(const PoseEstimate& estimate,
                      const std::vector<PairIndex>& in_graph) override {
    job_.set_pose_graph_optimised(estimate.optimised);
    if (estimate.optimised) {
      spdlog::info("job {} pose graph optimised: {} loop closures, {} of {} edges kept",
                   job_.job_id(), estimate.loop_closures, in_graph.size(), estimate.kept.size());
    }
  }

  void StageStarted(MapStage stage, int total) override {
    SetStage(stage, 0, static_cast<uint32_t>(total));
  }

  // The pipeline's hook before fusion (MapPipelineHooks).
  void PrepareFusion() {
    const std::string dir = ctx_.data_dir.CreateJobDir(job_.job_id());
    RemoveStagingFiles(dir);
    VerifyScans();  // fusion reads every scan again; the registrations took a while
    fuse_start_ = Clock::now();
  }

  void AssemblyStep(const AssemblyProgress& p) override {
    const v1::JobStage stage = rpc::JobStageOf(p.stage);
    const bool new_stage = stage != job_.stage_code();
    if (new_stage) rpc::SetJobStage(job_, stage);
    job_.set_stage_done(static_cast<uint32_t>(p.done));
    job_.set_stage_total(static_cast<uint32_t>(p.total));
    if (p.stage == MapStage::kFusing && p.done > 0) {
      const double elapsed = std::chrono::duration<double>(Clock::now() - fuse_start_).count();
      job_.set_eta_seconds(elapsed / p.done * (p.total - p.done));
    }
    if (new_stage) {
      Publish(nullptr);  // watchers see "writing" begin, not a second later
    } else {
      MaybePublishProgress();
    }
  }

  void SetCounts(const PairCounts& counts) {
    job_.set_pairs_done(static_cast<uint32_t>(counts.done));
    job_.set_pairs_doubtful(static_cast<uint32_t>(counts.doubtful));
    job_.set_pairs_total(static_cast<uint32_t>(counts.total));
    job_.set_stage_done(job_.pairs_done());
    job_.set_stage_total(job_.pairs_total());
    UpdateEta();
  }

  // Pairs finish at the rate seen so far in this run; the ETA counts down
  // between completions.
  void UpdateEta() {
    if (done_this_run_ == 0 || job_.stage_code() != v1::JOB_STAGE_REGISTERING) return;
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

  void SetStage(MapStage stage, uint32_t done, uint32_t total) {
    rpc::SetJobStage(job_, rpc::JobStageOf(stage));
    job_.set_stage_done(done);
    job_.set_stage_total(total);
    job_.set_eta_seconds(-1.0);
    Persist();
    Publish(nullptr);
  }

  // ---- Endings -------------------------------------------------------------
  RunOutcome Finish(const MapPipelineResult& result) {
    const std::string job_dir = ctx_.data_dir.JobDir(job_.job_id());
    const MapOutputPaths outputs = JobOutputPaths(job_dir);
    RequireOutputsWritten(outputs);
    const AssembledMap& map = result.map;
    const std::vector<int>& drive_starts = spec_.batch.pairing.drive_starts;
    if (!drive_starts.empty()) {
      WriteDriveTrajectories(spec_.batch.scans, map.estimate.poses, drive_starts,
                             DriveTrajectoryStems(job_dir, drive_starts.size() + 1));
    }
    spdlog::info(
        "job {} fused {} scans in {:.1f} s: {} occupied leaves, {} cloud points", job_.job_id(),
        spec_.batch.scans.size() - (map.untrusted_left_out ? map.untrusted_scans.size() : 0),
        map.fusion.seconds, map.fusion.occupied_leaves, map.fusion.cloud_points);
    if (map.fusion.points_out_of_range > 0) {
      spdlog::warn("job {}: {} points lie beyond the OctoMap's key range and were left out",
                   job_.job_id(), map.fusion.points_out_of_range);
    }
    const LoopStageSummary loops = SummariseLoops(result.pairs, map.in_graph);
    job_.clear_untrusted_scans();
    for (const int scan : map.untrusted_scans)
      job_.add_untrusted_scans(static_cast<uint32_t>(scan));
    job_.set_untrusted_left_out(map.untrusted_left_out);
    job_.set_loop_candidates(static_cast<uint32_t>(loops.candidates));
    job_.set_loops_closed(static_cast<uint32_t>(loops.closed));
    for (const std::string& line :
         {BridgeSummaryLine(result.pairs),
          UntrustedScansLine(spec_.batch.scans, map.untrusted_scans, map.untrusted_left_out),
          loops.Line()}) {
      if (!line.empty()) spdlog::info("job {}: {}", job_.job_id(), line);
    }
    std::vector<v1::TrajectoryPose> trajectory;
    const std::vector<double> stamps = ScanTimestamps(spec_.batch.scans);
    for (size_t i = 0; i < spec_.batch.scans.size(); ++i) {
      v1::TrajectoryPose pose;
      pose.set_index(static_cast<uint32_t>(i));
      pose.set_scan_id(spec_.scan_ids[i]);
      rpc::TransformToProto(map.estimate.poses[i], pose.mutable_pose());
      pose.set_timestamp(stamps[i]);
      trajectory.push_back(std::move(pose));
    }
    ctx_.store.PutTrajectory(job_.job_id(), trajectory);
    return End(v1::JOB_STATE_SUCCEEDED, "");
  }

  RunOutcome EndAfterStop() {
    if (control_.cancelled()) return End(v1::JOB_STATE_CANCELLED, "");
    if (control_.past_deadline()) {
      std::ostringstream error;
      error << "the job ran longer than this daemon's limit of " << ctx_.max_job_seconds
            << " s (--max-job-seconds)";
      return End(v1::JOB_STATE_FAILED, error.str());
    }
    spdlog::info("job {} interrupted by shutdown after {} of {} pairs; it resumes on restart",
                 job_.job_id(), job_.pairs_done(), job_.pairs_total());
    return RunOutcome::kInterrupted;
  }

  RunOutcome End(v1::JobState state, const std::string& error) {
    job_.set_state(state);
    rpc::SetJobStage(job_, state == v1::JOB_STATE_SUCCEEDED ? v1::JOB_STAGE_DONE
                           : state == v1::JOB_STATE_FAILED  ? v1::JOB_STAGE_FAILED
                                                            : v1::JOB_STAGE_CANCELLED);
    job_.set_error(WithoutServerPaths(error));  // the log below keeps the whole message
    job_.set_finished_at(rpc::NowSeconds());
    job_.set_eta_seconds(state == v1::JOB_STATE_SUCCEEDED ? 0.0 : -1.0);
    job_.set_cancel_requested(control_.cancelled());
    // Watchers learn a final state only once it is stored: one that was not
    // stays RUNNING in the store, and the next daemon resumes the job.
    try {
      Persist();
    } catch (const std::exception& e) {
      spdlog::error("job {}: cannot record the final state {}: {}", job_.job_id(),
                    rpc::JobStateName(state), e.what());
      return RunOutcome::kFailed;
    }
    Publish(nullptr);
    const double took = job_.finished_at() - job_.started_at();
    if (state == v1::JOB_STATE_FAILED) {
      spdlog::error("job {} failed after {:.1f} s: {}", job_.job_id(), took, error);
      return RunOutcome::kFailed;
    }
    spdlog::info("job {} {} after {:.1f} s ({} of {} pairs; {})", job_.job_id(),
                 rpc::JobStateName(state), took, job_.pairs_done(), job_.pairs_total(),
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
    if (control_.cancelled()) job_.set_cancel_requested(true);
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
  JobPairStore* pairs_ = nullptr;  // during the pipeline only
  std::string failure_;            // the first failed pair, named
  int done_this_run_ = 0;
  Clock::time_point run_start_;
  Clock::time_point last_progress_;
  Clock::time_point last_done_;  // when this run last finished a pair
  Clock::time_point fuse_start_;
};

}  // namespace

RunOutcome RunJob(const RunnerContext& context, JobControl& control, ::boicp::v1::Job job) {
  JobRun run(context, control, std::move(job));
  return run.Run();
}

}  // namespace boicp::server
