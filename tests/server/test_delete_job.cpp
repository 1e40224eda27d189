// DeleteJob: a finished job goes with its rows and outputs, a running one
// stays, and a folder a killed deletion left behind is removed at start.

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gmock/gmock.h>

#include "../support/demo_sequence.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class DeleteJob : public ServerTest {
 protected:
  // The status code of `call`, OK when it does not throw.
  template <typename Call>
  static grpc::StatusCode CodeOf(Call call, std::string* message = nullptr) {
    try {
      call();
    } catch (const rpc::RpcError& e) {
      if (message != nullptr) *message = e.what();
      return e.code();
    }
    return grpc::StatusCode::OK;
  }
};

TEST_F(DeleteJob, AFinishedJobGoesWithItsOutputsAndItsScansStay) {
  StartDaemon();
  auto client = Client();
  const auto ids = UploadDrive(client, 3, 61);
  const std::string job_id = client.Submit(QuickBatch(ids)).job_id();
  ASSERT_EQ(client.Watch(job_id).state(), v1::JOB_STATE_SUCCEEDED);
  const fs::path outputs = data_dir_ / "jobs" / job_id;
  ASSERT_TRUE(fs::exists(outputs / "map.bt"));

  const v1::DeleteJobResponse deleted = client.Delete(job_id);
  EXPECT_EQ(deleted.job_id(), job_id);
  EXPECT_GT(deleted.bytes_freed(), 1000u);
  EXPECT_FALSE(fs::exists(outputs));
  EXPECT_EQ(CodeOf([&] { client.GetJob(job_id); }), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(CodeOf([&] { client.Results(job_id); }), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(CodeOf([&] { client.Delete(job_id); }), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(client.ListJobs(10).jobs_size(), 0);
  // The scans serve the next job without another upload.
  EXPECT_EQ(client.Watch(client.Submit(QuickBatch(ids)).job_id()).state(), v1::JOB_STATE_SUCCEEDED);
}

TEST_F(DeleteJob, ARunningJobIsRefusedUntilCancelled) {
  StartDaemon({"--workers", "1", "--jobs", "1"});
  auto client = Client();
  const std::string job_id = client.Submit(SlowBatch(UploadDrive(client, 4, 62))).job_id();
  std::string message;
  EXPECT_EQ(CodeOf([&] { client.Delete(job_id); }, &message),
            grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(message, HasSubstr("cancel it first (boicp cancel " + job_id + ")"));
  client.Cancel(job_id);
  ASSERT_EQ(client.Watch(job_id).state(), v1::JOB_STATE_CANCELLED);
  EXPECT_EQ(client.Delete(job_id).job_id(), job_id);
  EXPECT_EQ(CodeOf([&] { client.GetJob(job_id); }), grpc::StatusCode::NOT_FOUND);
}

// --retain-days 0.00003 (2.6 s): a finished job goes by itself.
TEST_F(DeleteJob, FinishedJobsPastTheirRetentionAreDeleted) {
  StartDaemon({"--workers", "2", "--retain-days", "0.00003"});
  auto client = Client();
  const std::string job_id = client.Submit(QuickBatch(UploadDrive(client, 3, 64))).job_id();
  ASSERT_EQ(client.Watch(job_id).state(), v1::JOB_STATE_SUCCEEDED);
  // The rows go first, then the folder (JobManager::Delete): wait for both.
  const auto started = std::chrono::steady_clock::now();
  while ((CodeOf([&] { client.GetJob(job_id); }) == grpc::StatusCode::OK ||
          fs::exists(data_dir_ / "jobs" / job_id)) &&
         std::chrono::steady_clock::now() - started < std::chrono::seconds(60)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  EXPECT_EQ(CodeOf([&] { client.GetJob(job_id); }), grpc::StatusCode::NOT_FOUND);
  EXPECT_FALSE(fs::exists(data_dir_ / "jobs" / job_id));
}

// The stored-data cap: a daemon filled to --max-stored-gb refuses the next
// upload, and deleting the job that used the scans frees the room (its
// outputs, then its scans, unused for longer than --scan-grace-hours).
TEST_F(DeleteJob, AFullDaemonRefusesUploadsUntilAJobIsDeleted) {
  const std::vector<GeneratedScan> drive = MakeDemoSequence(4, 65);
  uint64_t three = 0;
  for (int i = 0; i < 3; ++i) three += drive[static_cast<size_t>(i)].kitti_bytes.size();
  const uint64_t cap = three + drive[3].kitti_bytes.size() / 2;
  constexpr double kGraceSeconds = 5.0;
  StartDaemon({"--workers", "2", "--max-stored-gb", std::to_string(static_cast<double>(cap) / 1e9),
               "--scan-grace-hours", std::to_string(kGraceSeconds / 3600.0)});
  auto client = Client();
  v1::ScanMetadata metadata;
  metadata.set_format(v1::SCAN_FORMAT_KITTI_BIN);
  std::vector<std::string> ids;
  for (int i = 0; i < 3; ++i) {
    ids.push_back(client.Upload(drive[static_cast<size_t>(i)].kitti_bytes, metadata).scan_id());
  }
  const auto uploaded = std::chrono::steady_clock::now();
  const std::string job_id = client.Submit(QuickBatch(ids)).job_id();
  ASSERT_EQ(client.Watch(job_id).state(), v1::JOB_STATE_SUCCEEDED);

  std::string message;
  EXPECT_EQ(CodeOf([&] { client.Upload(drive[3].kitti_bytes, metadata); }, &message),
            grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(message, HasSubstr("over --max-stored-gb"));
  EXPECT_THAT(message, HasSubstr("boicp delete"));

  std::this_thread::sleep_until(uploaded + std::chrono::duration<double>(kGraceSeconds + 0.5));
  EXPECT_GT(client.Delete(job_id).bytes_freed(), 0u);
  for (const std::string& id : ids) {
    EXPECT_FALSE(fs::exists(data_dir_ / "scans" / id.substr(0, 2) / id)) << id;
  }
  EXPECT_EQ(CodeOf([&] { client.Upload(drive[3].kitti_bytes, metadata); }), grpc::StatusCode::OK);
}

// An uploaded scan no batch takes goes after its grace period; the daemon
// then says it lacks it.
TEST_F(DeleteJob, AScanNoJobUsesIsCollectedAfterItsGrace) {
  StartDaemon({"--workers", "1", "--scan-grace-hours", std::to_string(1.0 / 3600.0)});
  auto client = Client();
  const std::string id = UploadDrive(client, 1, 66).front();
  const fs::path file = data_dir_ / "scans" / id.substr(0, 2) / id;
  const auto started = std::chrono::steady_clock::now();
  while (fs::exists(file) &&
         std::chrono::steady_clock::now() - started < std::chrono::seconds(30)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  EXPECT_FALSE(fs::exists(file));
  EXPECT_EQ(CodeOf([&] {
              client.Submit(QuickBatch({id, id}));
            }),
            grpc::StatusCode::INVALID_ARGUMENT);
}

// A daemon killed between the rows' transaction and the folder's removal
// leaves a folder no job owns: the next start removes it, and only it.
TEST_F(DeleteJob, AFolderNoJobOwnsIsRemovedAtStart) {
  StartDaemon();
  auto client = Client();
  const std::string kept = client.Submit(QuickBatch(UploadDrive(client, 3, 63))).job_id();
  ASSERT_EQ(client.Watch(kept).state(), v1::JOB_STATE_SUCCEEDED);
  StopDaemon();
  const fs::path orphan = data_dir_ / "jobs" / "job-999999";
  fs::create_directories(orphan);
  std::ofstream(orphan / "map.bt") << "left by a deletion the daemon did not finish";
  StartDaemon();
  EXPECT_FALSE(fs::exists(orphan));
  EXPECT_TRUE(fs::exists(data_dir_ / "jobs" / kept / "map.bt"));
  EXPECT_EQ(Client().GetJob(kept).state(), v1::JOB_STATE_SUCCEEDED);
}

}  // namespace
}  // namespace boicp::test
