// Durability: a daemon killed with SIGKILL mid-batch, or drained with
// SIGTERM, resumes the unfinished pairs after a restart, recomputes none of
// the finished ones, and ends with the same results as an uninterrupted run.

#include <signal.h>

#include <chrono>
#include <map>

#include <gmock/gmock.h>

#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::map<std::pair<uint32_t, uint32_t>, v1::PairResult> ByPair(const v1::JobResults& results) {
  std::map<std::pair<uint32_t, uint32_t>, v1::PairResult> pairs;
  for (const v1::PairResult& p : results.pairs()) pairs[{p.source(), p.target()}] = p;
  return pairs;
}

class Resume : public ServerTest {};

TEST_F(Resume, SigkillMidBatchThenRestartFinishesWithIdenticalResults) {
  // One worker, so pairs finish one at a time and the kill lands between them.
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const auto ids = UploadDrive(client, 7, 31);
  const v1::SubmitBatchRequest request = QuickBatch(ids, 17);
  const std::string job_id = client.Submit(request).job_id();

  const v1::Job partial = PollJob(
      client, job_id, [](const v1::Job& j) { return j.pairs_done() >= 2; }, 120);
  daemon_->Signal(SIGKILL);
  ASSERT_EQ(daemon_->Wait(10), 128 + SIGKILL);
  ASSERT_GE(partial.pairs_done(), 2u);
  ASSERT_LT(partial.pairs_done(), 6u) << "the batch finished before the kill";
  const double killed_at = NowSeconds();

  StartDaemon({"--workers", "1"});
  EXPECT_THAT(daemon_->Log(), HasSubstr("job " + job_id + " resumes"));
  client = Client();
  const v1::Job done = client.Watch(job_id);
  ASSERT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
  const v1::JobResults resumed = client.Results(job_id);
  ASSERT_EQ(resumed.pairs_size(), 6);

  // Nothing finished before the kill was computed again.
  int before_kill = 0;
  for (const v1::PairResult& p : resumed.pairs()) before_kill += p.finished_at() < killed_at;
  EXPECT_GE(before_kill, static_cast<int>(partial.pairs_done()));
  EXPECT_LT(before_kill, 6);

  // The same batch again, uninterrupted, gives the same pairs and poses.
  const v1::Job again = client.Watch(client.Submit(request).job_id());
  ASSERT_EQ(again.state(), v1::JOB_STATE_SUCCEEDED);
  const v1::JobResults reference = client.Results(again.job_id());
  const auto a = ByPair(resumed), b = ByPair(reference);
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [key, pair] : a) {
    const v1::PairResult& other = b.at(key);
    EXPECT_EQ(pair.seed(), other.seed());
    for (int k = 0; k < 16; ++k) {
      EXPECT_NEAR(pair.transform().m(k), other.transform().m(k), 1e-9)
          << "pair " << key.first << "->" << key.second;
    }
    EXPECT_NEAR(pair.objective(), other.objective(), 1e-9);
  }
  for (int i = 0; i < resumed.trajectory_size(); ++i) {
    for (int k = 0; k < 16; ++k) {
      EXPECT_NEAR(resumed.trajectory(i).pose().m(k), reference.trajectory(i).pose().m(k), 1e-9);
    }
  }
}

TEST_F(Resume, SigtermDrainsCheckpointsAndExitsThenResumes) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const std::string job_id = client.Submit(QuickBatch(UploadDrive(client, 5, 41))).job_id();
  PollJob(
      client, job_id, [](const v1::Job& j) { return j.pairs_done() >= 1; }, 120);
  daemon_->Signal(SIGTERM);
  EXPECT_EQ(daemon_->Wait(15), 0);
  const std::string log = daemon_->Log();
  EXPECT_THAT(log, HasSubstr("draining"));
  EXPECT_THAT(log, HasSubstr("stopped"));

  StartDaemon({"--workers", "1"});
  client = Client();
  const v1::Job done = client.Watch(job_id);
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
  EXPECT_EQ(done.pairs_done(), 4u);
}

// A job the daemon died in twice (as when it is killed for memory) would
// take every restart down again: the third start fails it, naming why.
TEST_F(Resume, JobTheDaemonDiedInTwiceFailsInsteadOfResuming) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const std::string job_id = client.Submit(SlowBatch(UploadDrive(client, 3, 41))).job_id();
  for (int death = 0; death < 2; ++death) {
    // This daemon's own log says it runs the job (the store said RUNNING
    // already), and the job read says so too: the log line may appear between
    // a read of the still queued job and the check.
    const v1::Job running = PollJob(
        client, job_id,
        [&](const v1::Job& job) {
          return job.state() == v1::JOB_STATE_RUNNING &&
                 daemon_->Log().find("job " + job_id + " running") != std::string::npos;
        },
        120);
    ASSERT_EQ(running.state(), v1::JOB_STATE_RUNNING);
    daemon_->Signal(SIGKILL);
    ASSERT_EQ(daemon_->Wait(10), 128 + SIGKILL);
    StartDaemon({"--workers", "1"});
    client = Client();
  }
  const v1::Job failed = client.GetJob(job_id);
  EXPECT_EQ(failed.state(), v1::JOB_STATE_FAILED);
  EXPECT_THAT(failed.error(), HasSubstr("stopped unexpectedly"));
  EXPECT_THAT(daemon_->Log(), Not(HasSubstr("job " + job_id + " resumes")));
}

}  // namespace
}  // namespace boicp::test
