// A job's budgets: the fusion bomb (one scan twice, at 1 cm leaves and rays
// of 200 m) is refused at submission with its estimate, and the daemon stays
// small; a job past --max-job-seconds fails, naming the flag.

#include <filesystem>
#include <iostream>

#include <gmock/gmock.h>

#include "../support/files_and_processes.hpp"
#include "../support/memory_bombs.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr uint64_t kFusionBombPeakRssMb = 400;

// A batch of one scan twice, to be fused at 1 cm leaves with rays of 200 m:
// within every per-setting limit, and about 10^8 cells.
v1::SubmitBatchRequest FusionBomb(const std::string& scan_id) {
  v1::SubmitBatchRequest request = QuickBatch({scan_id, scan_id});
  request.mutable_map()->set_resolution(0.01);
  request.mutable_map()->set_max_range(200.0);
  return request;
}

class JobBudgets : public ServerTest {
 protected:
  void ExpectRefused(rpc::MapBuilderClient& client, const std::string& scan_id,
                     const std::string& name) {
    const grpc::Status status = StatusOf([&] { client.Submit(FusionBomb(scan_id)); });
    const uint64_t peak_mb = PeakRssMb(daemon_->pid());
    std::cout << name << ": " << status.error_code() << " '" << status.error_message()
              << "', daemon peak RSS " << peak_mb << " MB\n";
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << name;
    EXPECT_THAT(status.error_message(), HasSubstr("needs an estimated")) << name;
    EXPECT_THAT(status.error_message(), HasSubstr("limit of 1024 MB (--max-fusion-mb)")) << name;
    EXPECT_LT(peak_mb, kFusionBombPeakRssMb) << name;
  }
};

TEST_F(JobBudgets, TheFusionBombIsRefusedAtSubmissionAndTheDaemonStaysSmall) {
  StartDaemon({"--workers", "2", "--max-fusion-mb", "1024"});
  auto client = Client();
  ExpectRefused(client, UploadDrive(client, 1, 91).at(0), "generated scan");

  // The bomb: a real KITTI sweep.
  const fs::path velodyne = fs::path(BOICP_SHARED_DATA_DIR) / "kitti00" / "velodyne";
  if (!fs::is_directory(velodyne)) {
    std::cout << "KITTI bomb skipped: " << velodyne << " is absent\n";
  } else {
    const std::string bytes = Slurp(*fs::directory_iterator(velodyne));
    const std::string scan_id =
        client.Upload(bytes, Meta(v1::SCAN_FORMAT_KITTI_BIN, bytes.size())).scan_id();
    ExpectRefused(client, scan_id, "KITTI sweep");
  }
  ASSERT_EQ(daemon_->Wait(0.1), -1) << "the daemon exited";

  // The same scan at the leaves and range the quick batches use is accepted.
  const std::string scan_id = UploadDrive(client, 1, 91).at(0);
  const v1::Job job = client.Watch(client.Submit(QuickBatch({scan_id, scan_id})).job_id());
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error();
}

// Map settings left to the scans are chosen, and checked, when the job starts.
TEST_F(JobBudgets, AFusionBombWithAnAutomaticRayCutFailsWhenItStarts) {
  StartDaemon({"--workers", "2", "--max-fusion-mb", "64"});
  auto client = Client();
  v1::SubmitBatchRequest request = FusionBomb(UploadDrive(client, 1, 91).at(0));
  request.mutable_map()->set_resolution(0.05);  // 0.01 with no given cut is refused by ray length
  request.mutable_map()->clear_max_range();
  const v1::Job job = client.Watch(client.Submit(request).job_id());
  EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED);
  EXPECT_THAT(job.error(), HasSubstr("limit of 64 MB (--max-fusion-mb)"));
  EXPECT_EQ(job.pairs_done(), 0u);
}

TEST_F(JobBudgets, AVoxelTooFineForTheScansIsRefusedNamingIt) {
  StartDaemon({"--workers", "2"});
  auto client = Client();
  v1::SubmitBatchRequest request = QuickBatch(UploadDrive(client, 2, 91));
  request.mutable_config()->set_refine_voxel(1e-9);
  const grpc::Status status = StatusOf([&] { client.Submit(request); });
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("refine_voxel: 1e-09 m is finer than"));
}

TEST_F(JobBudgets, AJobPastItsDeadlineFailsNamingTheFlag) {
  StartDaemon({"--workers", "2", "--max-job-seconds", "1"});
  auto client = Client();
  const std::string job_id = client.Submit(SlowBatch(UploadDrive(client, 4, 62))).job_id();
  const v1::Job job = client.Watch(job_id);
  EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED);
  EXPECT_THAT(job.error(), HasSubstr("longer than this daemon's limit of 1 s (--max-job-seconds)"));
  EXPECT_LT(job.finished_at() - job.started_at(), 30.0);
}

}  // namespace
}  // namespace boicp::test
