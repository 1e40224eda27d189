// Every limit of the daemon, exceeded once: RESOURCE_EXHAUSTED with the
// limit's value and its flag in the message, while a request at the limit
// still passes.

#include <sys/statvfs.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <thread>

#include <gmock/gmock.h>

#include "../support/demo_sequence.hpp"
#include "boicp/util/elapsed.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
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

// An upload the server has read the metadata of, held open (no bytes, no
// end), so that it keeps its slot and its announced bytes in the budget.
struct HeldUpload {
  std::unique_ptr<grpc::ClientContext> context;
  v1::UploadScanResponse response;
  std::unique_ptr<grpc::ClientWriter<v1::UploadScanRequest>> writer;

  grpc::Status End() {
    if (!writer) return grpc::Status::OK;
    writer->WritesDone();
    const grpc::Status status = writer->Finish();
    writer.reset();
    return status;
  }
};

// Ends what `held` held and opens an upload of `metadata` in it (the
// metadata sent, then a pause for the server to read it).
void Hold(rpc::MapBuilderClient& client, const v1::ScanMetadata& metadata, HeldUpload& held) {
  held.End();
  held.context = std::make_unique<grpc::ClientContext>();
  held.writer = client.stub().UploadScan(held.context.get(), &held.response);
  v1::UploadScanRequest message;
  *message.mutable_metadata() = metadata;
  held.writer->Write(message);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

// Holds an upload of `metadata` open in `held` and runs `probe`, starting
// over until the probe fails, at most 50 times: the server may read the
// probe's metadata before the held one's, and then the held upload is the
// one refused. Returns the probe's last status.
grpc::Status ProbeWhileHeld(rpc::MapBuilderClient& client, const v1::ScanMetadata& metadata,
                            const std::function<grpc::Status()>& probe, HeldUpload& held) {
  grpc::Status status;
  for (int attempt = 0; attempt < 50 && status.ok(); ++attempt) {
    Hold(client, metadata, held);
    status = probe();
  }
  return status;
}

// Uploads streaming at once are bounded, in number and in announced bytes.
TEST_F(Limits, UploadsInFlight) {
  StartDaemon(
      {"--workers", "1", "--max-concurrent-uploads", "1", "--max-upload-bytes-in-flight", "1000"});
  auto client = Client();
  HeldUpload held;
  grpc::Status status = ProbeWhileHeld(
      client, Meta(v1::SCAN_FORMAT_XYZ, XyzScan(3).size()),
      [&] { return RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, XyzScan(2).size()), {XyzScan(2)}); },
      held);
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("(--max-concurrent-uploads 1)"));
  v1::UploadScanRequest message;
  message.set_chunk(XyzScan(3));
  ASSERT_TRUE(held.writer->Write(message));
  EXPECT_TRUE(held.End().ok()) << "the upload holding the slot completes";

  const std::string big = XyzScan(200);  // over 1000 bytes
  status = RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, big.size()), {big});
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("(--max-upload-bytes-in-flight)"));
  EXPECT_TRUE(RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, XyzScan(2).size()), {XyzScan(2)}).ok());
}

// A metadata-only upload naming a stored scan makes the daemon re-hash (and
// may make it re-parse) the stored bytes: it is charged their size in the
// budget, so a few bytes cannot start more work than uploads of the bytes.
TEST_F(Limits, ReusingStoredBytesCountsTheirSizeInTheBudget) {
  StartDaemon({"--workers", "1", "--max-upload-bytes-in-flight", "1000"});
  auto client = Client();
  const std::string stored = XyzScan(100);  // 690 bytes
  const std::string id = client.Upload(stored, Meta(v1::SCAN_FORMAT_XYZ, stored.size())).scan_id();
  v1::ScanMetadata reuse = Meta(v1::SCAN_FORMAT_XYZ, stored.size());
  reuse.set_sha256(id);
  HeldUpload held;  // announces 500 bytes: 690 more is over 1000
  const grpc::Status status = ProbeWhileHeld(
      client, Meta(v1::SCAN_FORMAT_XYZ, 500), [&] { return RawUpload(client, reuse, {}); }, held);
  EXPECT_EQ(status.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("690 more"));
  held.End();
  EXPECT_TRUE(RawUpload(client, reuse, {}).ok()) << "alone, the reuse fits";
}

// Uploads in flight cannot together pass the free-space check: each one
// counts the bytes the others announced and have yet to write. The reserve
// leaves 8 GiB free for uploads; two of 4.8 GiB do not fit. (Other work on
// the disk may move its free space by up to 1.6 GiB without changing that.)
TEST_F(Limits, ConcurrentUploadsCannotTogetherPassTheFreeSpaceCheck) {
  struct statvfs fs {};
  ASSERT_EQ(::statvfs(dir_.c_str(), &fs), 0);
  const uint64_t free_bytes = static_cast<uint64_t>(fs.f_bavail) * fs.f_frsize;
  constexpr uint64_t kHeadroom = 8ull << 30;
  if (free_bytes < kHeadroom + (4ull << 30)) {
    GTEST_SKIP() << "needs 12 GiB free beside the data directory, " << (free_bytes >> 20)
                 << " MiB are";
  }
  const uint64_t each = kHeadroom / 10 * 6;
  StartDaemon({"--workers", "1", "--min-free-mb", std::to_string((free_bytes - kHeadroom) >> 20),
               "--max-scan-bytes", std::to_string(each), "--max-upload-bytes-in-flight",
               std::to_string(4 * each)});
  auto client = Client();
  // Announced but never sent: a probe that passes the check ends with
  // INVALID_ARGUMENT (no bytes came), one refused by it FAILED_PRECONDITION.
  const auto probe = [&] {
    const grpc::Status status = RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, each), {});
    return status.error_code() == Code::INVALID_ARGUMENT ? grpc::Status::OK : status;
  };
  HeldUpload held;
  const grpc::Status status = ProbeWhileHeld(client, Meta(v1::SCAN_FORMAT_XYZ, each), probe, held);
  EXPECT_EQ(status.error_code(), Code::FAILED_PRECONDITION) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("(--min-free-mb "));
  // The reserve is named; how much the daemon's disk has free is not.
  EXPECT_THAT(status.error_message(), Not(HasSubstr("free;")));
  EXPECT_THAT(status.error_message(), Not(HasSubstr(data_dir_.string())));
  held.End();
  EXPECT_TRUE(probe().ok()) << "alone, an upload of the same size passes the check";
}

// One connection carries at most --max-concurrent-streams calls at once: a
// call waits while two open uploads hold the connection's two streams, and
// goes through once one of them ends.
TEST_F(Limits, ConcurrentStreamsPerConnection) {
  StartDaemon({"--workers", "1", "--max-concurrent-streams", "2"});
  auto client = Client();
  const auto get_job = [&client](int deadline_s) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(deadline_s));
    v1::GetJobRequest request;
    request.set_job_id("job-999999");
    v1::Job job;
    return client.stub().GetJob(&context, request, &job).error_code();
  };
  // Connects, so that the client knows the server's stream limit.
  const grpc::StatusCode answered = get_job(60);
  ASSERT_EQ(answered, Code::NOT_FOUND);
  HeldUpload first, second;
  Hold(client, Meta(v1::SCAN_FORMAT_XYZ, 10), first);
  Hold(client, Meta(v1::SCAN_FORMAT_XYZ, 10), second);
  EXPECT_EQ(get_job(2), Code::DEADLINE_EXCEEDED) << "a third call on the connection went through";
  first.End();
  EXPECT_EQ(get_job(60), answered);
}

// Retries a small upload for up to 30 s while it is refused for want of a
// slot: the daemon frees a slot when gRPC next calls the ended upload back,
// a moment after its client has heard the end.
grpc::Status UploadOnceASlotIsFree(rpc::MapBuilderClient& client) {
  grpc::Status next;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  do {
    next = RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, XyzScan(2).size()), {XyzScan(2)});
    if (next.error_code() != Code::RESOURCE_EXHAUSTED) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  } while (std::chrono::steady_clock::now() < give_up);
  return next;
}

// Opens an upload with a deadline far beyond the daemon's limits and sends
// `metadata`; null when the metadata could not be sent.
std::unique_ptr<grpc::ClientWriter<v1::UploadScanRequest>> OpenUpload(
    rpc::MapBuilderClient& client, grpc::ClientContext& context, v1::UploadScanResponse& response,
    const v1::ScanMetadata& metadata) {
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
  auto writer = client.stub().UploadScan(&context, &response);
  v1::UploadScanRequest message;
  *message.mutable_metadata() = metadata;
  if (!writer->Write(message)) return nullptr;
  return writer;
}

// An upload that sends its metadata and then nothing, on a connection that
// stays alive, is cancelled after --upload-idle-timeout, and its slot is
// free again. (The client's own deadline, far later, ends it otherwise.)
TEST_F(Limits, SilentUploadIsCancelled) {
  StartDaemon({"--workers", "1", "--max-concurrent-uploads", "1", "--upload-idle-timeout", "1"});
  auto client = Client();
  grpc::ClientContext context;
  v1::UploadScanResponse response;
  auto writer = OpenUpload(client, context, response, Meta(v1::SCAN_FORMAT_XYZ, 100));
  ASSERT_TRUE(writer);
  const grpc::Status status = writer->Finish();  // the client sends nothing more
  EXPECT_EQ(status.error_code(), Code::CANCELLED) << status.error_message();
  const grpc::Status next = UploadOnceASlotIsFree(client);
  EXPECT_TRUE(next.ok()) << "the slot is free again: " << next.error_message();
}

// An upload that sends one byte and stalls is under --min-upload-kib-per-s
// once --upload-rate-grace has passed: it ends long before the idle timeout
// (60 s, which alone let it hold its slot that long), and the slot is free.
TEST_F(Limits, StalledUploadIsCutAfterTheRateGrace) {
  StartDaemon({"--workers", "1", "--max-concurrent-uploads", "1", "--upload-rate-grace", "1",
               "--min-upload-kib-per-s", "64"});
  auto client = Client();
  grpc::ClientContext context;
  v1::UploadScanResponse response;
  const auto start = std::chrono::steady_clock::now();
  auto writer = OpenUpload(client, context, response, Meta(v1::SCAN_FORMAT_XYZ, 100000));
  ASSERT_TRUE(writer);
  v1::UploadScanRequest message;
  message.set_chunk("0");
  ASSERT_TRUE(writer->Write(message));
  const grpc::Status status = writer->Finish();  // the client sends nothing more
  const double took = SecondsSince(start);
  EXPECT_THAT(status.error_code(), ::testing::AnyOf(Code::CANCELLED, Code::DEADLINE_EXCEEDED))
      << status.error_message();
  EXPECT_LT(took, 30.0) << "cut by the rate, not by the 60 s idle timeout";
  EXPECT_THAT(daemon_->Log(), HasSubstr("(--min-upload-kib-per-s, --upload-rate-grace)"));
  const grpc::Status next = UploadOnceASlotIsFree(client);
  EXPECT_TRUE(next.ok()) << "the slot is free again: " << next.error_message();
  // Its temp file goes when gRPC releases the call.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!std::filesystem::is_empty(data_dir_ / "tmp") &&
         std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(std::filesystem::is_empty(data_dir_ / "tmp")) << "the cut upload's temp file stayed";
  std::cout << "stalled upload ended after " << took << " s\n";
}

// One byte every 200 ms never trips the idle timeout, but is far under the
// minimum rate: the upload ends, naming the flag when the status reaches the
// client (the reactor's own check), or cancelled by the watchdog. (gRPC lets
// the client's writes succeed for a few seconds after the status is sent;
// the slot is free from the status on.)
TEST_F(Limits, TricklingUploadIsCutAfterTheRateGrace) {
  StartDaemon({"--workers", "1", "--max-concurrent-uploads", "1", "--upload-rate-grace", "1",
               "--min-upload-kib-per-s", "64", "--upload-idle-timeout", "8"});
  auto client = Client();
  grpc::ClientContext context;
  v1::UploadScanResponse response;
  const auto start = std::chrono::steady_clock::now();
  auto writer = OpenUpload(client, context, response, Meta(v1::SCAN_FORMAT_XYZ, 100000));
  ASSERT_TRUE(writer);
  v1::UploadScanRequest message;
  message.set_chunk("0");
  while (SecondsSince(start) < 30.0 && writer->Write(message)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  writer->WritesDone();
  const grpc::Status status = writer->Finish();
  const double took = SecondsSince(start);
  EXPECT_LT(took, 30.0) << "the trickle kept the upload open";
  if (status.error_code() == Code::DEADLINE_EXCEEDED) {
    EXPECT_THAT(status.error_message(), HasSubstr("(--min-upload-kib-per-s"));
  } else {
    EXPECT_EQ(status.error_code(), Code::CANCELLED) << status.error_message();
  }
  EXPECT_THAT(daemon_->Log(), HasSubstr("(--min-upload-kib-per-s, --upload-rate-grace)"));
  EXPECT_TRUE(UploadOnceASlotIsFree(client).ok());
  std::cout << "trickling upload ended after " << took << " s with status " << status.error_code()
            << ": " << status.error_message() << "\n";
}

// An upload naming a stored hash is answered after its metadata: it holds
// no slot while its client keeps the stream open, sends the bytes anyway or
// sends nothing more.
TEST_F(Limits, UploadNamingAStoredHashIsAnsweredAfterItsMetadata) {
  StartDaemon({"--workers", "1", "--max-concurrent-uploads", "1"});
  auto client = Client();
  const std::string stored = XyzScan(100);
  const std::string id = client.Upload(stored, Meta(v1::SCAN_FORMAT_XYZ, stored.size())).scan_id();
  v1::ScanMetadata reuse = Meta(v1::SCAN_FORMAT_XYZ, stored.size());
  reuse.set_sha256(id);

  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
  v1::UploadScanResponse response;
  auto writer = client.stub().UploadScan(&context, &response);
  v1::UploadScanRequest message;
  *message.mutable_metadata() = reuse;
  ASSERT_TRUE(writer->Write(message));
  const grpc::Status status = writer->Finish();  // neither bytes nor WritesDone
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.scan_id(), id);
  EXPECT_TRUE(response.already_present());
  EXPECT_EQ(response.num_points(), 100u);

  // A client that sends the bytes regardless (it raced another uploader) is
  // answered too, and the store's copy is unchanged.
  EXPECT_TRUE(RawUpload(client, reuse, {stored.substr(0, 300), stored.substr(300)}).ok());
  EXPECT_TRUE(client.Upload(stored, Meta(v1::SCAN_FORMAT_XYZ, stored.size())).already_present());
  EXPECT_TRUE(UploadOnceASlotIsFree(client).ok());
}

// WatchJob streams are bounded across all clients: over --max-watch-streams
// a new one is RESOURCE_EXHAUSTED naming the flag, and once a stream ends
// a new one is accepted.
TEST_F(Limits, WatchStreamsOverTheCapAreRefused) {
  StartDaemon({"--workers", "1", "--max-watch-streams", "2"});
  auto client = Client();
  const std::string job_id = client.Submit(SlowBatch(UploadDrive(client, 2, 37))).job_id();
  struct Watch {
    grpc::ClientContext context;
    std::unique_ptr<grpc::ClientReader<v1::JobEvent>> reader;
    v1::JobEvent first;
    bool started = false;
  };
  const auto open = [&](Watch& watch) {
    v1::WatchJobRequest request;
    request.set_job_id(job_id);
    watch.context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
    watch.reader = client.stub().WatchJob(&watch.context, request);
    watch.started = watch.reader->Read(&watch.first);
  };
  Watch first, second, third;
  open(first);
  open(second);
  ASSERT_TRUE(first.started && second.started);
  open(third);
  EXPECT_FALSE(third.started);
  const grpc::Status refused = third.reader->Finish();
  EXPECT_EQ(refused.error_code(), Code::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("(--max-watch-streams 2)"));

  first.context.TryCancel();
  first.reader->Finish();
  // The daemon counts the stream out when gRPC releases it, a moment later.
  bool accepted = false;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!accepted && std::chrono::steady_clock::now() < give_up) {
    auto again = std::make_unique<Watch>();
    open(*again);
    accepted = again->started;
    if (accepted) {
      again->context.TryCancel();
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    again->reader->Finish();
  }
  EXPECT_TRUE(accepted) << "a stream ended, yet a new one is still refused";
  client.Cancel(job_id);
  second.context.TryCancel();
  second.reader->Finish();
}

// GetResults is paged, so neither the reply nor its copy in the daemon grows
// with the job; the client gathers the pages into the same results.
TEST_F(Limits, GetResultsIsPagedAndTheClientGathersEveryPage) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const v1::Job done = client.Watch(client.Submit(QuickBatch(UploadDrive(client, 4, 41))).job_id());
  ASSERT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
  const v1::JobResults whole = client.Results(done.job_id());
  ASSERT_EQ(whole.pairs_size(), 3);
  ASSERT_EQ(whole.trajectory_size(), 4);

  const auto page = [&](uint32_t size, const std::string& token, v1::JobResults& results) {
    grpc::ClientContext context;
    v1::GetResultsRequest request;
    request.set_job_id(done.job_id());
    request.set_page_size(size);
    request.set_page_token(token);
    return client.stub().GetResults(&context, request, &results);
  };
  v1::JobResults first, last;
  ASSERT_TRUE(page(2, "", first).ok());
  EXPECT_EQ(first.pairs_size(), 2);
  EXPECT_EQ(first.trajectory_size(), 2);
  ASSERT_FALSE(first.next_page_token().empty());
  ASSERT_TRUE(page(2, first.next_page_token(), last).ok());
  EXPECT_EQ(last.pairs_size(), 1);
  EXPECT_EQ(last.trajectory_size(), 2);
  EXPECT_TRUE(last.next_page_token().empty()) << "every result was sent";

  const v1::JobResults gathered = client.Results(done.job_id(), 1);
  ASSERT_EQ(gathered.pairs_size(), whole.pairs_size());
  ASSERT_EQ(gathered.trajectory_size(), whole.trajectory_size());
  for (int i = 0; i < whole.pairs_size(); ++i) {
    EXPECT_EQ(gathered.pairs(i).SerializeAsString(), whole.pairs(i).SerializeAsString()) << i;
  }
  for (int i = 0; i < whole.trajectory_size(); ++i) {
    EXPECT_EQ(gathered.trajectory(i).SerializeAsString(), whole.trajectory(i).SerializeAsString())
        << i;
  }

  v1::JobResults refused;
  const grpc::Status status = page(2, "12:x", refused);
  EXPECT_EQ(status.error_code(), Code::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("page_token"));
}

}  // namespace
}  // namespace boicp::test
