// A scan's metadata is written once, by its first upload: a second client
// naming the same bytes with another reading of them is refused; one sending
// another timestamp, prior pose or sensor origin is a reuse that changes
// nothing stored, and the first client's next batch reads its scans as it
// uploaded them. A batch that needs another context sends it
// (SubmitBatchRequest.scan_context), and each job keeps its own, across a
// restart too.

#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <signal.h>

#include <gmock/gmock.h>

#include "../support/demo_sequence.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::HasSubstr;
using Code = grpc::StatusCode;

// A generated scan as XYZ text, padded with a comment to a multiple of 16
// bytes so that the same bytes also load as a KITTI .bin: two readings a
// daemon would accept.
std::string XyzAlsoReadableAsKitti(const std::string& kitti_bytes) {
  std::string text;
  char line[96];
  for (size_t at = 0; at + 16 <= kitti_bytes.size(); at += 16) {
    float xyz[3];
    std::memcpy(xyz, kitti_bytes.data() + at, sizeof(xyz));
    std::snprintf(line, sizeof(line), "%.9g %.9g %.9g\n", xyz[0], xyz[1], xyz[2]);
    text += line;
  }
  size_t pad = (16 - text.size() % 16) % 16;
  if (pad < 2) pad += 16;  // room for "#" and "\n"
  return text + "#" + std::string(pad - 2, ' ') + "\n";
}

double FirstUploadStamp(size_t i) { return 100.5 + static_cast<double>(i); }

class ScanMetadataOnce : public ServerTest {};

TEST_F(ScanMetadataOnce, AnotherClientsUploadCannotChangeWhatTheFirstClientsBatchReads) {
  StartDaemon({"--workers", "2"});
  auto first = Client();
  std::vector<std::string> bytes, ids;
  for (const GeneratedScan& scan : MakeDemoSequence(3, 71)) {
    v1::ScanMetadata metadata;
    metadata.set_format(v1::SCAN_FORMAT_XYZ);
    metadata.set_timestamp(FirstUploadStamp(ids.size()));
    bytes.push_back(XyzAlsoReadableAsKitti(scan.kitti_bytes));
    ids.push_back(first.Upload(bytes.back(), metadata).scan_id());
  }

  // A second client on its own channel names scan 0's hash, reading its
  // bytes as a KITTI .bin...
  auto second = Client();
  v1::ScanMetadata as_kitti = Meta(v1::SCAN_FORMAT_KITTI_BIN, bytes[0].size());
  as_kitti.set_sha256(ids[0]);
  as_kitti.set_timestamp(FirstUploadStamp(0));
  grpc::Status status = RawUpload(second, as_kitti, {});
  EXPECT_EQ(status.error_code(), Code::FAILED_PRECONDITION) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("scan " + ids[0] +
                                                " is stored with other metadata: format (stored "
                                                "SCAN_FORMAT_XYZ, sent SCAN_FORMAT_KITTI_BIN)"));

  // ...and sends scan 1's bytes with another timestamp, prior pose and
  // sensor origin, and names scan 2 with another timestamp: reuses, and the
  // stored records stay as the first client uploaded them.
  v1::ScanMetadata moved = Meta(v1::SCAN_FORMAT_XYZ, bytes[1].size());
  moved.set_timestamp(7.0);
  moved.mutable_sensor_origin()->set_z(5.0);
  rpc::TransformToProto(Transform::Identity(), moved.mutable_prior_pose());
  status = RawUpload(second, moved, {bytes[1]});
  EXPECT_TRUE(status.ok()) << status.error_message();
  v1::ScanMetadata renamed = Meta(v1::SCAN_FORMAT_XYZ, bytes[2].size());
  renamed.set_sha256(ids[2]);
  renamed.set_timestamp(9.0);
  EXPECT_TRUE(second.Upload(bytes[2], renamed).already_present());
  EXPECT_TRUE(second.Upload(bytes[1], moved).already_present());
  EXPECT_THAT(daemon_->Log(), HasSubstr("an upload with other metadata refused: format"));

  // The same metadata is reused as before, by either client.
  v1::ScanMetadata same;
  same.set_format(v1::SCAN_FORMAT_XYZ);
  same.set_timestamp(FirstUploadStamp(1));
  EXPECT_TRUE(second.Upload(bytes[1], same).already_present());
  EXPECT_TRUE(first.Upload(bytes[1], same).already_present());

  // The first client's next batch, from a client that sends no scan context
  // (written for the older proto), reads the scans as it uploaded them.
  std::string job_id;
  const grpc::Status submitted = StatusOf([&] { job_id = first.Submit(QuickBatch(ids)).job_id(); });
  ASSERT_TRUE(submitted.ok()) << submitted.error_message();
  const v1::Job job = first.Watch(job_id);
  ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error();
  EXPECT_EQ(job.settings().scan_format(), v1::SCAN_FORMAT_XYZ);
  const v1::JobResults results = first.Results(job_id);
  ASSERT_EQ(results.trajectory_size(), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(results.trajectory(i).timestamp(), FirstUploadStamp(static_cast<size_t>(i)))
        << "scan " << i;
  }
}

// The context each job of ContextsOfTwoBatches sends: scan i at
// `first_stamp` + i seconds, with or without priors `offset` * T_world_scan.
v1::SubmitBatchRequest BatchWithContext(const std::vector<std::string>& ids,
                                        const std::vector<Transform>& truth, double first_stamp,
                                        const std::optional<Transform>& offset) {
  v1::SubmitBatchRequest request = QuickBatch(ids);
  for (size_t i = 0; i < ids.size(); ++i) {
    v1::ScanContext& context = *request.add_scan_context();
    context.set_timestamp(first_stamp + static_cast<double>(i));
    if (offset) rpc::TransformToProto(*offset * truth[i], context.mutable_prior_pose());
  }
  return request;
}

TEST_F(ScanMetadataOnce, TheSameScansInTwoBatchesEachUseTheirOwnContextAcrossARestart) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  std::vector<Transform> truth;
  const std::vector<std::string> ids = UploadDrive(client, 3, 73, &truth);

  // A batch whose context is wrong is refused, naming the entry.
  v1::SubmitBatchRequest bad = BatchWithContext(ids, truth, 10, std::nullopt);
  bad.mutable_scan_context(1)->mutable_prior_pose()->add_m(1.0);
  grpc::Status status = StatusOf([&] { client.Submit(bad); });
  EXPECT_EQ(status.error_code(), Code::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("scan_context[1].prior_pose: a transform has 16"));
  bad = BatchWithContext(ids, truth, 10, std::nullopt);
  bad.mutable_scan_context(2)->mutable_sensor_origin()->set_y(std::nan(""));
  status = StatusOf([&] { client.Submit(bad); });
  EXPECT_EQ(status.error_code(), Code::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("scan_context[2].sensor_origin: non-finite"));
  bad = BatchWithContext(ids, truth, 10, std::nullopt);
  bad.mutable_scan_context()->RemoveLast();
  status = StatusOf([&] { client.Submit(bad); });
  EXPECT_EQ(status.error_code(), Code::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("scan_context: 2 entries for 3 scan_ids"));

  // The same scans, twice: timestamps 10.. and no priors, then timestamps
  // 20.. and priors in a world 100 m away. Both queued, then the daemon is
  // killed: each job's context must come back from the store.
  Transform offset = Transform::Identity();
  offset(0, 3) = 100.0;
  const std::string plain = client.Submit(BatchWithContext(ids, truth, 10, std::nullopt)).job_id();
  const std::string with_priors = client.Submit(BatchWithContext(ids, truth, 20, offset)).job_id();
  daemon_->Signal(SIGKILL);
  ASSERT_EQ(daemon_->Wait(10), 128 + SIGKILL);
  StartDaemon({"--workers", "1"});
  EXPECT_THAT(daemon_->Log(), HasSubstr("job " + with_priors + " resumes"));
  client = Client();

  for (const auto& [job_id, first_stamp] : {std::pair{plain, 10.0}, std::pair{with_priors, 20.0}}) {
    const v1::Job job = client.Watch(job_id);
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job_id << ": " << job.error();
    const v1::JobResults results = client.Results(job_id);
    ASSERT_EQ(results.trajectory_size(), 3) << job_id;
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(results.trajectory(i).timestamp(), first_stamp + i) << job_id << " scan " << i;
    }
    // The map frame is scan 0's, or its prior pose's world.
    const Transform first =
        rpc::TransformFromProto(results.trajectory(0).pose(), "trajectory[0].pose");
    const Transform expected =
        job_id == plain ? Transform(Transform::Identity()) : Transform(offset * truth[0]);
    EXPECT_TRUE(first.isApprox(expected, 1e-6)) << job_id << ":\n" << first;
  }

  // The stored records kept the context of the first upload (none): a batch
  // that sends none gets the scan index as timestamps.
  const v1::Job stored = client.Watch(client.Submit(QuickBatch(ids)).job_id());
  ASSERT_EQ(stored.state(), v1::JOB_STATE_SUCCEEDED) << stored.error();
  const v1::JobResults results = client.Results(stored.job_id());
  ASSERT_EQ(results.trajectory_size(), 3);
  EXPECT_EQ(results.trajectory(2).timestamp(), 2.0);
}

}  // namespace
}  // namespace boicp::test
