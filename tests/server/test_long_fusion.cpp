// A cancel and a drain that arrive while a job fuses a scan for seconds end
// that scan's fusion at once, not after it: the cancelled job ends with no
// scan fused, and the drained daemon stops within its grace period, then
// the job resumes and succeeds with every output.

#include <cmath>
#include <csignal>
#include <filesystem>
#include <thread>

#include <gmock/gmock.h>

#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// An XYZ scan whose fusion at 1 cm leaves takes seconds yet builds a small
// tree: points every 30 cm out to 100 m on 100 rays from the sensor. Each
// point casts a ray of up to 10,000 cells, and all of them share the cells
// of 100 lines. `seed` turns the star, so that two scans differ.
std::string StarScan(int seed) {
  constexpr int kRays = 100;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  std::string text;
  char line[96];
  for (int r = 0; r < kRays; ++r) {
    const double z = 1.0 - 2.0 * (r + 0.5) / kRays;
    const double radius = std::sqrt(1.0 - z * z);
    const double angle = golden * r + 0.01 * seed;
    for (double d = 1.0; d <= 100.0; d += 0.3) {
      std::snprintf(line, sizeof line, "%.3f %.3f %.3f\n", d * radius * std::cos(angle),
                    d * radius * std::sin(angle), d * z);
      text += line;
    }
  }
  return text;
}

class LongFusion : public ServerTest {
 protected:
  // Submits two star scans at 1 cm leaves and waits until fusion has begun
  // its first scan: "fusing" is published just before, and a moment later
  // the first between-scans check has passed, seconds before the scan ends.
  std::string SubmitAndWaitForFusion(rpc::MapBuilderClient& client) {
    std::vector<std::string> ids;
    for (int seed = 0; seed < 2; ++seed) {
      const std::string scan = StarScan(seed);
      ids.push_back(client.Upload(scan, Meta(v1::SCAN_FORMAT_XYZ, scan.size())).scan_id());
    }
    v1::SubmitBatchRequest request = QuickBatch(ids);
    request.mutable_map()->set_resolution(0.01);
    request.mutable_map()->set_max_range(150.0);
    const std::string job_id = client.Submit(request).job_id();
    const v1::Job fusing = PollJob(
        client, job_id, [](const v1::Job& j) { return j.stage() == "fusing"; }, 300);
    EXPECT_EQ(fusing.stage(), "fusing") << fusing.error();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    return job_id;
  }
};

TEST_F(LongFusion, CancelEndsTheScanBeingFused) {
  StartDaemon({"--workers", "2"});
  auto client = Client();
  const std::string job_id = SubmitAndWaitForFusion(client);
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
  const std::string job_id = SubmitAndWaitForFusion(client);
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
