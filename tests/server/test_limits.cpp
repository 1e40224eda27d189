// Every limit of the daemon, exceeded once: RESOURCE_EXHAUSTED with the
// limit's value and its flag in the message, while a request at the limit
// still passes.

#include <gmock/gmock.h>

#include "demo_sequence.hpp"
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
  const auto drive = client::MakeDemoSequence(3, 5);
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
  v1::SubmitBatchRequest slow = QuickBatch(UploadDrive(client, 3, 81));
  slow.mutable_config()->set_preset("C");
  slow.mutable_config()->clear_random_samples();
  slow.mutable_config()->clear_iterations();
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

}  // namespace
}  // namespace boicp::test
