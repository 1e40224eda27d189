// The job store under concurrent writers: a job's final state, once stored,
// is never overwritten by a writer that read the job before it finished
// (a cancel racing with the job's completion), hundreds of times over.

#include <filesystem>
#include <thread>

#include <gtest/gtest.h>
#include <unistd.h>

#include "job_store.hpp"

namespace boicp::server {
namespace {

namespace fs = std::filesystem;

constexpr int kRaces = 400;

class JobStoreRaces : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("boicp_store_races_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    store_ = std::make_unique<JobStore>((dir_ / "jobs.sqlite").string());
  }
  void TearDown() override {
    store_.reset();
    fs::remove_all(dir_);
  }

  v1::Job RunningJob() {
    v1::Job job;
    job.set_state(v1::JOB_STATE_QUEUED);
    job = store_->CreateJob(job, JobInput{});
    job.set_state(v1::JOB_STATE_RUNNING);
    store_->UpdateJob(job);
    return job;
  }

  fs::path dir_;
  std::unique_ptr<JobStore> store_;
};

// Two threads released together: one finishes the job, the other cancels
// it, half the time as JobManager does (RequestCancel), half the time the
// way it used to (read the job, write it back marked cancel-requested).
TEST_F(JobStoreRaces, CancelRacingWithCompletionNeverLosesTheFinalState) {
  int lost = 0;
  for (int race = 0; race < kRaces; ++race) {
    const bool stale_write = race % 2 == 1;
    const v1::Job job = RunningJob();
    std::atomic<int> ready{0};
    auto start_together = [&ready] {
      ++ready;
      while (ready.load() < 2) std::this_thread::yield();
    };
    std::thread finisher([&] {
      v1::Job done = job;
      done.set_state(v1::JOB_STATE_SUCCEEDED);
      start_together();
      store_->UpdateJob(done);
    });
    std::thread canceller([&] {
      start_together();
      if (!stale_write) {
        store_->RequestCancel(job.job_id());
        return;
      }
      std::optional<v1::Job> seen = store_->GetJob(job.job_id());
      if (!seen) return;
      seen->set_cancel_requested(true);
      store_->UpdateJob(*seen);
    });
    finisher.join();
    canceller.join();
    const v1::Job final_job = *store_->GetJob(job.job_id());
    lost += final_job.state() != v1::JOB_STATE_SUCCEEDED;
  }
  std::cout << "cancel raced with completion " << kRaces << " times: " << lost
            << " final states lost\n";
  EXPECT_EQ(lost, 0);
}

}  // namespace
}  // namespace boicp::server
