// Every bad input of the issue gets its precise status, and the daemon stays
// up: INVALID_ARGUMENT, NOT_FOUND, UNAUTHENTICATED. Exceeded limits
// (RESOURCE_EXHAUSTED) are in test_limits.cpp.

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>

#include "../support/files_and_processes.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

class BadInput : public ServerTest {};

TEST_F(BadInput, EachCaseGetsItsStatusAndTheDaemonStaysUp) {
  StartDaemon({"--workers", "1", "--jobs", "1"});
  auto client = Client();
  using Code = grpc::StatusCode;

  // --- Uploads ---------------------------------------------------------------
  const std::string seventeen(17, 'x');
  EXPECT_EQ(RawUpload(client, Meta(v1::SCAN_FORMAT_KITTI_BIN, 17), {seventeen}).error_code(),
            Code::INVALID_ARGUMENT)
      << "malformed (truncated) KITTI scan";
  const std::string comment_only = "# no points at all\n";
  const grpc::Status empty =
      RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, comment_only.size()), {comment_only});
  EXPECT_EQ(empty.error_code(), Code::INVALID_ARGUMENT) << "empty cloud";
  EXPECT_THAT(empty.error_message(), HasSubstr("uploaded scan"));
  EXPECT_EQ(RawUpload(client, Meta(v1::SCAN_FORMAT_UNSPECIFIED, 3), {"abc"}).error_code(),
            Code::INVALID_ARGUMENT)
      << "no format";
  EXPECT_EQ(RawUpload(client, Meta(static_cast<v1::ScanFormat>(42), 3), {"abc"}).error_code(),
            Code::INVALID_ARGUMENT)
      << "unknown format";
  EXPECT_EQ(RawUpload(client, Meta(v1::SCAN_FORMAT_DEPTH_PNG, 3), {"abc"}).error_code(),
            Code::INVALID_ARGUMENT)
      << "depth image without intrinsics";
  EXPECT_EQ(RawUpload(client, Meta(v1::SCAN_FORMAT_PLY, 3), {"abc"}).error_code(),
            Code::INVALID_ARGUMENT)
      << "malformed PLY";
  EXPECT_EQ(RawUpload(client, Meta(v1::SCAN_FORMAT_XYZ, 10), {"1 2 3\n"}).error_code(),
            Code::INVALID_ARGUMENT)
      << "fewer bytes than announced";
  v1::ScanMetadata wrong_hash = Meta(v1::SCAN_FORMAT_XYZ, 6);
  wrong_hash.set_sha256(std::string(64, 'a'));
  EXPECT_EQ(RawUpload(client, wrong_hash, {"1 2 3\n"}).error_code(), Code::INVALID_ARGUMENT)
      << "hash mismatch";
  v1::ScanMetadata bad_prior = Meta(v1::SCAN_FORMAT_XYZ, 6);
  for (int k = 0; k < 16; ++k) bad_prior.mutable_prior_pose()->add_m(2.0);
  EXPECT_EQ(RawUpload(client, bad_prior, {"1 2 3\n"}).error_code(), Code::INVALID_ARGUMENT)
      << "prior pose that is not rigid";

  // --- Batches ---------------------------------------------------------------
  const auto ids = UploadDrive(client, 3, 81);
  auto submit_code = [&](const v1::SubmitBatchRequest& request) {
    return CodeOf([&] { client.Submit(request); });
  };
  v1::SubmitBatchRequest unknown = QuickBatch(ids);
  unknown.set_scan_ids(1, std::string(64, 'f'));
  EXPECT_EQ(submit_code(unknown), Code::INVALID_ARGUMENT) << "unknown scan id";
  // Scan ids never become paths: the API takes bytes, and ids must be hashes.
  unknown.set_scan_ids(1, "../../../../etc/passwd");
  EXPECT_EQ(submit_code(unknown), Code::INVALID_ARGUMENT) << "a path as scan id";
  EXPECT_EQ(MissingScans(client, {"../" + ids[0], ids[0]}),
            std::vector<std::string>{"../" + ids[0]});
  EXPECT_EQ(submit_code(QuickBatch({ids[0]})), Code::INVALID_ARGUMENT) << "one scan";
  v1::SubmitBatchRequest bad_voxel = QuickBatch(ids);
  bad_voxel.mutable_config()->set_voxel(-1.0);
  EXPECT_EQ(submit_code(bad_voxel), Code::INVALID_ARGUMENT) << "negative voxel";
  v1::SubmitBatchRequest bad_preset = QuickBatch(ids);
  bad_preset.mutable_config()->set_preset("Z");
  EXPECT_EQ(submit_code(bad_preset), Code::INVALID_ARGUMENT) << "unknown preset";
  v1::SubmitBatchRequest bad_bounds = QuickBatch(ids);
  bad_bounds.mutable_config()->mutable_rotation_bounds()->set_x(-0.1);
  EXPECT_EQ(submit_code(bad_bounds), Code::INVALID_ARGUMENT) << "negative bounds";
  v1::SubmitBatchRequest bad_pairs = QuickBatch(ids);
  bad_pairs.mutable_pairing()->set_mode(v1::PairingPolicy::MODE_EXPLICIT);
  bad_pairs.mutable_pairing()->add_pairs()->set_target(1);
  EXPECT_EQ(submit_code(bad_pairs), Code::INVALID_ARGUMENT) << "pairs leave scan 2 unconnected";
  v1::SubmitBatchRequest bad_map = QuickBatch(ids);
  bad_map.mutable_map()->set_resolution(-0.1);
  EXPECT_EQ(submit_code(bad_map), Code::INVALID_ARGUMENT) << "negative resolution";
  v1::SubmitBatchRequest bad_threshold = QuickBatch(ids);
  bad_threshold.mutable_pairing()->set_mode(v1::PairingPolicy::MODE_OVERLAP);
  bad_threshold.mutable_pairing()->set_overlap_threshold(1.5);
  EXPECT_EQ(submit_code(bad_threshold), Code::INVALID_ARGUMENT) << "overlap threshold";

  // --- Unknown jobs ----------------------------------------------------------
  EXPECT_EQ(CodeOf([&] { client.GetJob("job-999999"); }), Code::NOT_FOUND);
  EXPECT_EQ(CodeOf([&] { client.Cancel("job-999999"); }), Code::NOT_FOUND);
  EXPECT_EQ(CodeOf([&] { client.Results("job-999999"); }), Code::NOT_FOUND);
  EXPECT_EQ(CodeOf([&] { client.Watch("job-999999"); }), Code::NOT_FOUND);
  EXPECT_EQ(CodeOf([&] {
              client.ExportToFile("job-999999", v1::EXPORT_FORMAT_OCTOMAP_BT,
                                  (dir_ / "x").string());
            }),
            Code::NOT_FOUND);
  EXPECT_EQ(CodeOf([&] { client.GetJob(""); }), Code::INVALID_ARGUMENT);

  // --- An existing job, an unknown export format ------------------------------
  const std::string first = client.Submit(QuickBatch(ids)).job_id();
  EXPECT_EQ(CodeOf([&] {
              client.ExportToFile(first, static_cast<v1::ExportFormat>(77), (dir_ / "x").string());
            }),
            Code::INVALID_ARGUMENT)
      << "unknown export format";
  client.Cancel(first);

  // Still serving after all of that.
  EXPECT_EQ(client.GetJob(first).job_id(), first);
  EXPECT_EQ(daemon_->Wait(0.1), -1) << "the daemon exited";
}

TEST_F(BadInput, BearerTokenIsRequiredWhenConfigured) {
  const std::string token_file = (dir_ / "token").string();
  std::ofstream(token_file) << "s3cret-token\n";
  StartDaemon({"--workers", "1", "--auth-token-file", token_file});
  auto anonymous = Client();
  auto wrong = Client("not-the-token");
  auto right = Client("s3cret-token");
  using Code = grpc::StatusCode;

  for (auto* client : {&anonymous, &wrong}) {
    EXPECT_EQ(CodeOf([&] { client->GetJob("job-000001"); }), Code::UNAUTHENTICATED);
    EXPECT_EQ(CodeOf([&] { client->Submit(QuickBatch({"a", "b"})); }), Code::UNAUTHENTICATED);
    EXPECT_EQ(CodeOf([&] { client->Watch("job-000001"); }), Code::UNAUTHENTICATED);
    EXPECT_EQ(CodeOf([&] {
                client->ExportToFile("job-000001", v1::EXPORT_FORMAT_OCTOMAP_BT,
                                     (dir_ / "x").string());
              }),
              Code::UNAUTHENTICATED);
    EXPECT_EQ(CodeOf([&] { client->Upload("1 2 3\n", Meta(v1::SCAN_FORMAT_XYZ, 6)); }),
              Code::UNAUTHENTICATED);
    EXPECT_EQ(CodeOf([&] { client->ListJobs(); }), Code::UNAUTHENTICATED);
    EXPECT_EQ(CodeOf([&] { client->Cancel("job-000001"); }), Code::UNAUTHENTICATED);
    EXPECT_EQ(CodeOf([&] { client->Results("job-000001"); }), Code::UNAUTHENTICATED);
    grpc::ClientContext context;
    client->Authorize(context);
    v1::FindScansRequest find;
    find.add_scan_ids(std::string(64, 'a'));
    v1::FindScansResponse found;
    EXPECT_EQ(client->stub().FindScans(&context, find, &found).error_code(), Code::UNAUTHENTICATED);
  }
  EXPECT_EQ(RawUpload(anonymous, Meta(v1::SCAN_FORMAT_XYZ, 6), {"1 2 3\n"}).error_code(),
            Code::UNAUTHENTICATED);
  EXPECT_EQ(CodeOf([&] { right.GetJob("job-000001"); }), Code::NOT_FOUND);
  EXPECT_EQ(right.Upload("1 2 3\n4 5 6\n", Meta(v1::SCAN_FORMAT_XYZ, 0)).num_points(), 2u);

  // The scheme name is case-insensitive (RFC 6750); the token is not.
  const auto find_with = [&](const std::string& authorization) {
    grpc::ClientContext context;
    context.AddMetadata("authorization", authorization);
    v1::FindScansRequest find;
    find.add_scan_ids(std::string(64, 'a'));
    v1::FindScansResponse found;
    return anonymous.stub().FindScans(&context, find, &found).error_code();
  };
  EXPECT_EQ(find_with("bearer s3cret-token"), Code::OK);
  EXPECT_EQ(find_with("BEARER s3cret-token"), Code::OK);
  EXPECT_EQ(find_with("Bearer S3CRET-TOKEN"), Code::UNAUTHENTICATED);
  EXPECT_EQ(find_with("Bearers3cret-token"), Code::UNAUTHENTICATED);
}

// A token file others can read is named in the log with its fix; one only
// its owner reads is not.
TEST_F(BadInput, ATokenFileOthersCanReadIsWarnedAbout) {
  const std::filesystem::path token_file = dir_ / "token";
  std::ofstream(token_file) << "s3cret-token\n";
  std::filesystem::permissions(
      token_file, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                      std::filesystem::perms::group_read | std::filesystem::perms::others_read);
  StartDaemon({"--workers", "1", "--auth-token-file", token_file.string()});
  EXPECT_THAT(daemon_->Log(), HasSubstr("is open to group or others (mode 0644): chmod 600 " +
                                        token_file.string()));

  std::filesystem::permissions(
      token_file, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  StartDaemon({"--workers", "1", "--auth-token-file", token_file.string()});
  EXPECT_THAT(daemon_->Log(), Not(HasSubstr("auth token file")));
}

// An empty BOICPD_AUTH_TOKEN_FILE reads as "no flag" to the option parser;
// it must stop the daemon instead of turning authentication off.
TEST_F(BadInput, EmptyAuthTokenVariableRefusesToStart) {
  const RunResult run =
      RunCaptured(std::string("BOICPD_AUTH_TOKEN_FILE= timeout 60 ") + BOICPD_PATH +
                      " --listen 127.0.0.1:0 --data-dir " + (dir_ / "data").string(),
                  dir_);
  const std::string output = run.out + run.err;
  EXPECT_EQ(run.exit_code, 2) << output;
  EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
  EXPECT_THAT(output, HasSubstr("BOICPD_AUTH_TOKEN_FILE is set but empty"));
}

// Closed by default: a daemon reachable beyond this machine starts only
// with a token (and TLS for it), or with the flag that opens it on purpose.
TEST_F(BadInput, ANonLoopbackListenNeedsATokenAndTlsOrAnInsecureFlag) {
  std::ofstream(dir_ / "token") << "s3cret\n";
  const auto boicpd = [&](const std::string& flags) {
    return RunCaptured("timeout 60 " + std::string(BOICPD_PATH) + " --data-dir " +
                           (dir_ / "data").string() + " " + flags,
                       dir_);
  };
  const RunResult open = boicpd("--listen 0.0.0.0:50051");
  EXPECT_EQ(open.exit_code, 2) << open.err;
  EXPECT_THAT(open.err, HasSubstr("--token-file"));
  EXPECT_THAT(open.err, HasSubstr("--insecure-no-auth"));

  const std::string token = " --token-file " + (dir_ / "token").string();
  const RunResult plaintext = boicpd("--listen 0.0.0.0:50051" + token);
  EXPECT_EQ(plaintext.exit_code, 2) << plaintext.err;
  EXPECT_THAT(plaintext.err, HasSubstr("plaintext"));
  EXPECT_THAT(plaintext.err, HasSubstr("--insecure"));

  // The opt-ins start (and a SIGTERM from timeout drains them: exit 0).
  for (const std::string& flags : {std::string("--insecure-no-auth"), "--insecure" + token}) {
    const RunResult started =
        RunCaptured("timeout --preserve-status -s TERM 3 " + std::string(BOICPD_PATH) +
                        " --data-dir " + (dir_ / "data").string() + " --listen 0.0.0.0:0 " + flags,
                    dir_);
    EXPECT_EQ(started.exit_code, 0) << flags << "\n" << started.err;
    EXPECT_THAT(started.out + started.err, HasSubstr("listening on")) << flags;
  }
}

}  // namespace
}  // namespace boicp::test
