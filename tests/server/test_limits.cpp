// Every limit of the daemon, exceeded once: RESOURCE_EXHAUSTED with the
// limit's value and its flag in the message, while a request at the limit
// still passes.

#include <chrono>
#include <memory>
#include <thread>

#include <gmock/gmock.h>

#include "../support/demo_sequence.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::HasSubstr;
using Code = grpc::StatusCode;

// An XYZ text scan of `n` distinct points.
std::string XyzScan(int n) {
  std::string text;
  for (int i = 0; i < n; ++i) text += std::to_string(i) + " 1 2\n";
  return text;
}

class Limits : public ServerTest {};

TEST_F(Limits, MessageSize) {
  StartDaemon({"--workers", "1", "--max-message-bytes", "2000000"});
  auto client = Client();
  const std::string zeros(2500000, 0);  // a valid KITTI scan: 156,250 points at the origin
  const grpc::Status status = RawUpload(client, Meta(v1::SCAN_FORMAT_KITTI_BIN, 2500000), {zeros});
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("vs. 2000000)"));  // gRPC's own message
  // The same bytes in chunks under the limit are fine.
  EXPECT_TRUE(RawUpload(client, Meta(v1::SCAN_FORMAT_KITTI_BIN, 2500000),
                        {zeros.substr(0, 1500000), zeros.substr(1500000)})
                  .ok());
}

TEST_F(Limits, ScanBytes) {
  StartDaemon({"--workers", "1", "--max-scan-bytes", "3000000"});
  auto client = Client();
  const grpc::Status status = RawUpload(client, Meta(v1::SCAN_FORMAT_KITTI_BIN, 3000016), {});
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("limit of 3000000 (--max-scan-bytes)"));
  const std::string at_limit(3000000, 0);
  EXPECT_TRUE(RawUpload(client, Meta(v1::SCAN_FORMAT_KITTI_BIN, at_limit.size()),
                        {at_limit.substr(0, 2000000), at_limit.substr(2000000)})
                  .ok());
}

TEST_F(Limits, ScanPointsAtUploadAndAtSubmission) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const auto drive = test::MakeDemoSequence(3, 5);
  std::vector<std::string> ids;
  for (const auto& scan : drive) {
    ids.push_back(client.Upload(scan.kitti_bytes, Meta(v1::SCAN_FORMAT_KITTI_BIN, 0)).scan_id());
  }

  // A lower limit after a restart: new uploads, metadata updates of stored
  // scans, and batches of stored scans all meet it.
  StartDaemon({"--workers", "1", "--max-scan-points", "1000"});
  client = Client();
  const std::string over = XyzScan(1001);
  grpc::Status status = RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, over.size()), {over});
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(),
              HasSubstr("1001 points, over this daemon's limit of 1000 (--max-scan-points)"));
  const std::string at_limit = XyzScan(1000);
  EXPECT_TRUE(RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, at_limit.size()), {at_limit}).ok());

  status =
      StatusOf([&] { client.Upload(drive[0].kitti_bytes, Meta(v1::SCAN_FORMAT_KITTI_BIN, 0)); });
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED)
      << "metadata-only upload of a stored scan";
  EXPECT_THAT(status.error_message(), HasSubstr("limit of 1000 (--max-scan-points)"));

  status = StatusOf([&] { client.Submit(QuickBatch(ids)); });
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("scan_ids[0]"));
  EXPECT_THAT(status.error_message(), HasSubstr("limit of 1000 (--max-scan-points)"));
}

TEST_F(Limits, ScansPerBatch) {
  StartDaemon({"--workers", "1", "--max-batch-scans", "10"});
  auto client = Client();
  const std::string unknown(64, 'f');
  const grpc::Status status =
      StatusOf([&] { client.Submit(QuickBatch(std::vector<std::string>(11, unknown))); });
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("11 scans"));
  EXPECT_THAT(status.error_message(), HasSubstr("limit of 10 (--max-batch-scans)"));
  // Ten pass the limit and fail later, on the unknown id.
  EXPECT_EQ(CodeOf([&] { client.Submit(QuickBatch(std::vector<std::string>(10, unknown))); }),
            Code::INVALID_ARGUMENT);
}

TEST_F(Limits, QueuedJobs) {
  StartDaemon({"--workers", "1", "--jobs", "1", "--max-queued-jobs", "1"});
  auto client = Client();
  // Full preset C: slow enough that the first job is still running below.
  const v1::SubmitBatchRequest slow = SlowBatch(UploadDrive(client, 3, 81));
  const std::string first = client.Submit(slow).job_id();
  PollJob(
      client, first, [](const v1::Job& j) { return j.state() == v1::JOB_STATE_RUNNING; }, 30);
  const std::string second = client.Submit(slow).job_id();  // the one that may wait
  const grpc::Status status = StatusOf([&] { client.Submit(slow); });
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("(--max-queued-jobs 1)"));
  client.Cancel(second);
  client.Cancel(first);
}

// Settings that would make one job allocate or compute without bound are
// refused at submission, naming the field and its limit.
TEST_F(Limits, JobSettingsHaveUpperBounds) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const std::vector<std::string> ids = UploadDrive(client, 2, 31);
  const std::vector<std::pair<std::function<void(v1::SubmitBatchRequest&)>, std::string>> cases = {
      {[](auto& r) { r.mutable_config()->set_random_samples(1000000); },
       "config.random_samples: 1000000 is over the limit of 1000"},
      {[](auto& r) { r.mutable_config()->set_iterations(1000000); },
       "config.iterations: 1000000 is over the limit of 1000"},
      {[](auto& r) { r.mutable_config()->set_evaluation_points(4000000000u); },
       "config.evaluation_points: 4000000000 is over the limit of 1000000"},
      {[](auto& r) { r.mutable_config()->mutable_translation_bounds()->set_x(1e9); },
       "config.translation_bounds.x: 1e+09 is over the limit of 1000"},
      {[](auto& r) { r.mutable_config()->mutable_rotation_bounds()->set_z(4.0); },
       "config.rotation_bounds.z: 4 is over the limit of 3.14159"},
      {[](auto& r) { r.mutable_config()->set_max_range(1e6); },
       "config.max_range: 1e+06 is over the limit of 1000"},
      {[](auto& r) { r.mutable_map()->set_resolution(0.001); },
       "map.resolution: 0.001 is under the limit of 0.01"},
      {[](auto& r) { r.mutable_map()->set_max_range(1e6); },
       "map.max_range: 1e+06 is over the limit of 1000"},
      {[](auto& r) {
         r.mutable_map()->set_resolution(0.01);
         r.mutable_map()->set_max_range(0.0);
       },
       "over the limit of 20000"},
      {[](auto& r) { r.mutable_map()->set_cloud_voxel(1e-6); },
       "map.cloud_voxel: 1e-06 is under the limit of 0.01"},
      {[](auto& r) { r.set_label(std::string(10000, 'x')); },
       "label: 10000 bytes is over the limit of 256"}};
  for (const auto& [change, message] : cases) {
    v1::SubmitBatchRequest request = QuickBatch(ids);
    change(request);
    const grpc::Status status = StatusOf([&] { client.Submit(request); });
    EXPECT_EQ(status.error_code(), Code::INVALID_ARGUMENT) << message;
    EXPECT_THAT(status.error_message(), HasSubstr(message));
  }
  EXPECT_EQ(client.ListJobs().jobs_size(), 0) << "a job over a limit was queued";
}

// page_size is unsigned: 2^31 and more must clamp, not turn into a negative
// SQL limit (-1 lists nothing, other negatives list everything).
TEST_F(Limits, PageSizesOf2To31AndMoreClampToTheMaximum) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const std::string job_id = client.Submit(QuickBatch(UploadDrive(client, 2, 33))).job_id();
  for (const uint32_t size : {0x80000000u, 0xfffffffeu, 0xffffffffu}) {
    const v1::ListJobsResponse page = client.ListJobs(size);
    ASSERT_EQ(page.jobs_size(), 1) << "page_size " << size;
    EXPECT_EQ(page.jobs(0).job_id(), job_id);
  }
  client.Cancel(job_id);
}

// A label is free text: in the log it stays on its own line, escaped.
TEST_F(Limits, LabelsAreEscapedInTheLog) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  v1::SubmitBatchRequest request = QuickBatch(UploadDrive(client, 2, 35));
  request.set_label("survey\nFORGED error boicpd: fake line\x1b[2J");
  const std::string job_id = client.Submit(request).job_id();
  client.Cancel(job_id);
  const std::string log = daemon_->Log();
  EXPECT_THAT(log, HasSubstr("label 'survey\\nFORGED error boicpd: fake line\\x1b[2J'"));
  EXPECT_EQ(log.find("\nFORGED"), std::string::npos) << log;
  EXPECT_EQ(client.GetJob(job_id).label(), request.label()) << "the label itself is kept";
}

// Uploads streaming at once are bounded, in number and in announced bytes.
TEST_F(Limits, UploadsInFlight) {
  StartDaemon(
      {"--workers", "1", "--max-concurrent-uploads", "1", "--max-upload-bytes-in-flight", "1000"});
  auto client = Client();
  v1::UploadScanRequest message;
  *message.mutable_metadata() = Meta(v1::SCAN_FORMAT_XYZ, XyzScan(3).size());
  // An upload holds the one slot once the server has read its metadata. Until
  // then a second upload may take the slot first, and the open one is the
  // upload refused; so open one, give the server a moment, probe, and start
  // over (ending the open one) until the probe is the upload refused.
  v1::UploadScanResponse response;
  std::unique_ptr<grpc::ClientContext> context;
  std::unique_ptr<grpc::ClientWriter<v1::UploadScanRequest>> open_upload;
  grpc::Status status;
  for (int attempt = 0; attempt < 50 && status.ok(); ++attempt) {
    if (open_upload) {
      open_upload->WritesDone();
      open_upload->Finish();
    }
    context = std::make_unique<grpc::ClientContext>();
    open_upload = client.stub().UploadScan(context.get(), &response);
    ASSERT_TRUE(open_upload->Write(message));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    status = RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, XyzScan(2).size()), {XyzScan(2)});
  }
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("(--max-concurrent-uploads 1)"));
  message.set_chunk(XyzScan(3));
  ASSERT_TRUE(open_upload->Write(message));
  open_upload->WritesDone();
  EXPECT_TRUE(open_upload->Finish().ok()) << "the upload holding the slot completes";

  const std::string big = XyzScan(200);  // over 1000 bytes
  status = RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, big.size()), {big});
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("(--max-upload-bytes-in-flight)"));
  EXPECT_TRUE(RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, XyzScan(2).size()), {XyzScan(2)}).ok());
}

}  // namespace
}  // namespace boicp::test
