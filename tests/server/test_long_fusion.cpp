// A cancel and a drain that arrive while a job fuses a scan for seconds end
// that scan's fusion at once, not after it: the cancelled job ends with no
// scan fused, and the drained daemon stops within its grace period, then
// the job resumes and succeeds with every output.

#include <csignal>
#include <filesystem>
#include <thread>

#include <gmock/gmock.h>

#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

using LongFusion = ServerTest;

TEST_F(LongFusion, CancelEndsTheScanBeingFused) {
  StartDaemon({"--workers", "2"});
  auto client = Client();
  const std::string job_id = SubmitLongFusion(client);
  EXPECT_TRUE(client.Cancel(job_id).cancel_requested());
  const v1::Job end = client.Watch(job_id);
  EXPECT_EQ(end.state(), v1::JOB_STATE_CANCELLED);
  EXPECT_EQ(end.stage_done(), 0u) << "the first scan was fused to its end after the cancel";
  EXPECT_EQ(end.stage_total(), 2u);
  EXPECT_FALSE(std::filesystem::exists(data_dir_ / "jobs" / job_id / "map.bt"));
}

TEST_F(LongFusion, DrainStopsItWithinTheGracePeriodAndTheJobResumes) {
  const std::vector<std::string> args = {"--workers", "2", "--shutdown-grace", "2"};
  StartDaemon(args);
  auto client = Client();
  const std::string job_id = SubmitLongFusion(client);
  daemon_->Signal(SIGTERM);
  EXPECT_EQ(daemon_->Wait(60), 0);
  const std::string log = daemon_->Log();
  EXPECT_THAT(log, HasSubstr("job " + job_id + " interrupted by shutdown"));
  EXPECT_THAT(log, Not(HasSubstr("still stopping"))) << "the drain waited for the scan's fusion";

  StartDaemon(args);
  client = Client();
  const v1::Job done = client.Watch(job_id);
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
  EXPECT_TRUE(std::filesystem::is_regular_file(data_dir_ / "jobs" / job_id / "map.bt"));
}

}  // namespace
}  // namespace boicp::test
