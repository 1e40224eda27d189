// A scan's metadata is written once, by its first upload: a second client
// naming the same bytes with other metadata (another reading of them, or
// another timestamp, prior pose or sensor origin) is refused, and the first
// client's next batch reads its scans as it uploaded them.

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

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
  // sensor origin.
  v1::ScanMetadata moved = Meta(v1::SCAN_FORMAT_XYZ, bytes[1].size());
  moved.set_timestamp(7.0);
  moved.mutable_sensor_origin()->set_z(5.0);
  rpc::TransformToProto(Transform::Identity(), moved.mutable_prior_pose());
  status = RawUpload(second, moved, {bytes[1]});
  EXPECT_EQ(status.error_code(), Code::FAILED_PRECONDITION) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("sensor_origin (stored 0 0 0, sent 0 0 5)"));
  EXPECT_THAT(status.error_message(), HasSubstr("prior_pose (stored none, sent one)"));
  EXPECT_THAT(status.error_message(), HasSubstr("timestamp (stored 101.5, sent 7)"));
  EXPECT_THAT(status.error_message(), HasSubstr("send the stored metadata"));
  EXPECT_THAT(daemon_->Log(), HasSubstr("an upload with other metadata refused: format"));

  // The same metadata is reused as before, by either client.
  v1::ScanMetadata same;
  same.set_format(v1::SCAN_FORMAT_XYZ);
  same.set_timestamp(FirstUploadStamp(1));
  EXPECT_TRUE(second.Upload(bytes[1], same).already_present());
  EXPECT_TRUE(first.Upload(bytes[1], same).already_present());

  // The first client's next batch reads the scans as it uploaded them.
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

}  // namespace
}  // namespace boicp::test
