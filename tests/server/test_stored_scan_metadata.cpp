// What a re-upload of stored bytes must agree with (MetadataDifferences:
// how they decode, not their context), the job store keeping a scan's first
// record (JobStore::PutScan), and a batch's scan context kept with its job.

#include <optional>

#include <gmock/gmock.h>

#include "../support/files_and_processes.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "job_store.hpp"
#include "scan_metadata_once.hpp"
#include "service_error.hpp"

namespace boicp::server {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

v1::ScanMetadata DepthScan() {
  v1::ScanMetadata metadata;
  metadata.set_format(v1::SCAN_FORMAT_DEPTH_PNG);
  v1::DepthCamera& camera = *metadata.mutable_depth();
  camera.set_fx(525);
  camera.set_fy(525);
  camera.set_cx(319.5);
  camera.set_cy(239.5);
  camera.set_depth_scale(5000);
  return metadata;
}

TEST(MetadataDifferences, UnsetFieldsReadAsTheValuesJobsGiveThem) {
  v1::ScanMetadata stored = DepthScan(), sent = DepthScan();
  sent.mutable_sensor_origin()->set_x(-0.0);  // set to 0 0 0: what unset means
  sent.mutable_depth()->add_invalid_values(65535);
  sent.mutable_depth()->add_invalid_values(0);  // the default set, listed
  sent.set_size_bytes(123);                     // from the bytes, not the metadata
  sent.set_sha256(std::string(64, 'a'));
  EXPECT_THAT(MetadataDifferences(stored, sent), IsEmpty());

  v1::ScanMetadata kitti, kitti_with_camera = DepthScan();
  kitti.set_format(v1::SCAN_FORMAT_KITTI_BIN);
  kitti_with_camera.set_format(v1::SCAN_FORMAT_KITTI_BIN);  // a camera only a depth image reads
  EXPECT_THAT(MetadataDifferences(kitti, kitti_with_camera), IsEmpty());
}

TEST(MetadataDifferences, EachFieldThatDecodesTheBytesIsNamedWithBothValues) {
  const v1::ScanMetadata stored = DepthScan();
  v1::ScanMetadata sent = DepthScan();
  sent.mutable_depth()->set_fx(520.5);
  sent.mutable_depth()->set_depth_scale(1000);
  sent.mutable_depth()->add_invalid_values(0);
  EXPECT_THAT(
      MetadataDifferences(stored, sent),
      ElementsAre("depth.fx (stored 525, sent 520.5)", "depth.depth_scale (stored 5000, sent 1000)",
                  "depth.invalid_values (stored 0 65535, sent 0)"));

  v1::ScanMetadata ply = sent;
  ply.set_format(v1::SCAN_FORMAT_PLY);
  EXPECT_THAT(MetadataDifferences(sent, ply),
              ElementsAre("format (stored SCAN_FORMAT_DEPTH_PNG, sent SCAN_FORMAT_PLY)"));
}

// The context comes with each batch: another one is no difference.
TEST(MetadataDifferences, TheContextIsNotCompared) {
  const v1::ScanMetadata stored = DepthScan();
  v1::ScanMetadata sent = DepthScan();
  sent.mutable_sensor_origin()->set_z(0.1);
  rpc::TransformToProto(Transform::Identity(), sent.mutable_prior_pose());
  sent.set_timestamp(1317376860.123456);
  EXPECT_THAT(MetadataDifferences(stored, sent), IsEmpty());
  EXPECT_NO_THROW(RequireStoredMetadata("abc", stored, sent));
}

TEST(MetadataDifferences, ARefusalNamesTheScanAndWhatToDo) {
  v1::ScanMetadata sent = DepthScan();
  sent.mutable_depth()->set_cy(7);
  try {
    RequireStoredMetadata("abc", DepthScan(), sent);
    FAIL() << "not refused";
  } catch (const ServiceError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::FAILED_PRECONDITION);
    EXPECT_THAT(e.what(), HasSubstr("scan abc is stored with other metadata: depth.cy (stored "
                                    "239.5, sent 7). A scan's metadata is written once"));
    EXPECT_THAT(e.what(), HasSubstr("a batch sends its own (SubmitBatchRequest.scan_context)"));
    EXPECT_THAT(e.what(), HasSubstr("send the stored metadata"));
  }
  EXPECT_NO_THROW(RequireStoredMetadata("abc", DepthScan(), DepthScan()));
}

TEST(ScanRecords, TheFirstRecordStaysAndOnlyAMissingProfileIsFilledIn) {
  const test::ScratchDir dir("boicp_scan_records");
  {
    JobStore store((dir.path() / "jobs.sqlite").string());
    v1::ScanMetadata first = DepthScan();
    first.set_sha256(std::string(64, 'b'));
    first.set_timestamp(1);
    EXPECT_EQ(store.PutScan(first, 10, {}).num_points, 10u);  // no profile yet

    v1::ScanMetadata other = first;
    other.set_timestamp(2);
    RangeProfile profile;
    profile.counts = profile.ray_counts = profile.direction_counts = {1, 2};
    profile.max_range = 3;
    const StoredScan kept = store.PutScan(other, 99, profile);
    EXPECT_EQ(kept.metadata.timestamp(), 1);
    EXPECT_EQ(kept.num_points, 10u);
    EXPECT_TRUE(kept.ranges.empty()) << "a profile sent with other metadata is not kept";

    const StoredScan filled = store.PutScan(first, 99, profile);
    EXPECT_EQ(filled.num_points, 10u);
    EXPECT_EQ(filled.ranges.counts, profile.counts);
    EXPECT_EQ(store.GetScan(first.sha256())->metadata.timestamp(), 1);
  }
}

// A batch's scan context is part of the request stored with the job, so a
// resumed job reads it again; the scans' snapshot stays their stored records.
TEST(JobInputs, TheBatchsScanContextIsStoredWithTheJob) {
  const test::ScratchDir dir("boicp_job_inputs");
  {
    JobStore store((dir.path() / "jobs.sqlite").string());
    JobInput input;
    v1::ScanMetadata scan = DepthScan();
    scan.set_sha256(std::string(64, 'c'));
    scan.set_timestamp(1);
    for (int i = 0; i < 2; ++i) {
      input.request.add_scan_ids(scan.sha256());
      input.scans.push_back(scan);
      v1::ScanContext& context = *input.request.add_scan_context();
      context.set_timestamp(50 + i);
      rpc::TransformToProto(Transform::Identity(), context.mutable_prior_pose());
    }
    v1::Job job;
    job.set_state(v1::JOB_STATE_QUEUED);
    const std::string job_id = store.CreateJob(job, input).job_id();
    const std::optional<JobInput> read = store.GetJobInput(job_id);
    ASSERT_TRUE(read);
    ASSERT_EQ(read->request.scan_context_size(), 2);
    EXPECT_EQ(read->request.scan_context(1).timestamp(), 51);
    EXPECT_EQ(read->request.scan_context(1).prior_pose().m_size(), 16);
    ASSERT_EQ(read->scans.size(), 2u);
    EXPECT_EQ(read->scans[1].timestamp(), 1);
  }
}

}  // namespace
}  // namespace boicp::server
