// Health checking, server reflection, job listing with paging, and TLS.

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>

#include "../support/files_and_processes.hpp"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpc/reflection/v1alpha/reflection.grpc.pb.h"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::Contains;

class ServiceExtras : public ServerTest {};

TEST_F(ServiceExtras, HealthReflectionAndPagedListing) {
  StartDaemon({"--workers", "1", "--jobs", "1"});
  rpc::ConnectOptions options;
  options.address = daemon_->address();
  const auto channel = rpc::Connect(options);

  {
    auto health = grpc::health::v1::Health::NewStub(channel);
    grpc::ClientContext context;
    grpc::health::v1::HealthCheckResponse response;
    ASSERT_TRUE(health->Check(&context, {}, &response).ok());
    EXPECT_EQ(response.status(), grpc::health::v1::HealthCheckResponse::SERVING);
  }
  {
    auto reflection = grpc::reflection::v1alpha::ServerReflection::NewStub(channel);
    grpc::ClientContext context;
    auto stream = reflection->ServerReflectionInfo(&context);
    grpc::reflection::v1alpha::ServerReflectionRequest request;
    request.set_list_services("");
    ASSERT_TRUE(stream->Write(request));
    stream->WritesDone();
    grpc::reflection::v1alpha::ServerReflectionResponse response;
    ASSERT_TRUE(stream->Read(&response));
    std::vector<std::string> names;
    for (const auto& service : response.list_services_response().service()) {
      names.push_back(service.name());
    }
    EXPECT_THAT(names, Contains("boicp.v1.MapBuilder"));
    EXPECT_TRUE(stream->Finish().ok());
  }

  // Three jobs, cancelled at once; listed newest first, two per page.
  rpc::MapBuilderClient client(channel);
  const auto ids = UploadDrive(client, 2, 91);
  std::vector<std::string> jobs;
  for (int i = 0; i < 3; ++i) {
    jobs.push_back(client.Submit(QuickBatch(ids)).job_id());
    client.Cancel(jobs.back());
  }
  grpc::ClientContext first_context;
  v1::ListJobsRequest request;
  request.set_page_size(2);
  v1::ListJobsResponse first;
  ASSERT_TRUE(client.stub().ListJobs(&first_context, request, &first).ok());
  ASSERT_EQ(first.jobs_size(), 2);
  EXPECT_EQ(first.jobs(0).job_id(), jobs[2]);
  EXPECT_EQ(first.jobs(1).job_id(), jobs[1]);
  ASSERT_FALSE(first.next_page_token().empty());
  grpc::ClientContext second_context;
  request.set_page_token(first.next_page_token());
  v1::ListJobsResponse second;
  ASSERT_TRUE(client.stub().ListJobs(&second_context, request, &second).ok());
  ASSERT_EQ(second.jobs_size(), 1);
  EXPECT_EQ(second.jobs(0).job_id(), jobs[0]);
  EXPECT_TRUE(second.next_page_token().empty());

  grpc::ClientContext bad_context;
  request.set_page_token("not-a-token");
  v1::ListJobsResponse bad;
  EXPECT_EQ(client.stub().ListJobs(&bad_context, request, &bad).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

// Scans, maps and the job store are the users' data: nothing the daemon
// writes is readable by other users, and its lock file is its own alone.
TEST_F(ServiceExtras, NothingInTheDataDirectoryIsReadableByOthers) {
  namespace fs = std::filesystem;
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const std::string job_id = client.Submit(QuickBatch(UploadDrive(client, 2, 7))).job_id();
  ASSERT_EQ(client.Watch(job_id).state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(fs::status(data_dir_ / "lock").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  int checked = 0;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(data_dir_)) {
    EXPECT_EQ(entry.symlink_status().permissions() & fs::perms::others_all, fs::perms::none)
        << entry.path();
    ++checked;
  }
  EXPECT_GT(checked, 8);  // the store, the scans, the job's outputs
}

TEST_F(ServiceExtras, UploadsEveryFormatAndDeduplicatesByContent) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  auto meta = [](v1::ScanFormat format) {
    v1::ScanMetadata m;
    m.set_format(format);
    return m;
  };
  const std::string xyz = "0 0 0\n1 0 0\n0 1 0\n";
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  const std::string pcd =
      "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_EQ(client.Upload(xyz, meta(v1::SCAN_FORMAT_XYZ)).num_points(), 3u);
  EXPECT_EQ(client.Upload(ply, meta(v1::SCAN_FORMAT_PLY)).num_points(), 3u);
  EXPECT_EQ(client.Upload(pcd, meta(v1::SCAN_FORMAT_PCD)).num_points(), 3u);
  const v1::UploadScanResponse again = client.Upload(xyz, meta(v1::SCAN_FORMAT_XYZ));
  EXPECT_TRUE(again.already_present());
  EXPECT_EQ(again.scan_id(), rpc::ScanId(xyz));

  // A depth image needs its camera; 7-Scenes stores millimetres.
  const std::string png =
      std::string(BOICP_SHARED_DATA_DIR) + "/7scenes_redkitchen/depth/frame-000000.depth.png";
  std::ifstream in(png, std::ios::binary);
  if (!in) GTEST_SKIP() << "../shared/data/7scenes_redkitchen absent: depth upload not checked";
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  v1::ScanMetadata depth = meta(v1::SCAN_FORMAT_DEPTH_PNG);
  depth.mutable_depth()->set_fx(585);
  depth.mutable_depth()->set_fy(585);
  depth.mutable_depth()->set_cx(320);
  depth.mutable_depth()->set_cy(240);
  depth.mutable_depth()->set_depth_scale(1000);
  EXPECT_GT(client.Upload(bytes, depth).num_points(), 100000u);
}

TEST_F(ServiceExtras, ServesOverTls) {
  const std::string key = (dir_ / "key.pem").string(), cert = (dir_ / "cert.pem").string();
  if (!MakeSelfSignedCertificate(key, cert)) GTEST_SKIP() << "openssl is not available";
  StartDaemon({"--workers", "1", "--tls-cert", cert, "--tls-key", key});

  rpc::ConnectOptions tls;
  tls.address = daemon_->address();
  tls.tls_ca_file = cert;
  rpc::MapBuilderClient secure(rpc::Connect(tls));
  EXPECT_EQ(secure
                .Upload("1 2 3\n",
                        [] {
                          v1::ScanMetadata m;
                          m.set_format(v1::SCAN_FORMAT_XYZ);
                          return m;
                        }())
                .num_points(),
            1u);

  rpc::MapBuilderClient plain = Client();
  try {
    plain.GetJob("job-000001");
    ADD_FAILURE() << "a plaintext call to the TLS port succeeded";
  } catch (const rpc::RpcError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE);
  }
}

// The token travels inside TLS: without it a TLS call is refused, with it it passes.
TEST_F(ServiceExtras, TokenOverTls) {
  const std::string key = (dir_ / "key.pem").string(), cert = (dir_ / "cert.pem").string();
  if (!MakeSelfSignedCertificate(key, cert)) GTEST_SKIP() << "openssl is not available";
  std::ofstream(dir_ / "token") << "s3cret-token\n";
  StartDaemon({"--workers", "1", "--tls-cert", cert, "--tls-key", key, "--auth-token-file",
               (dir_ / "token").string()});
  rpc::ConnectOptions tls;
  tls.address = daemon_->address();
  tls.tls_ca_file = cert;
  rpc::MapBuilderClient anonymous(rpc::Connect(tls));
  rpc::MapBuilderClient right(rpc::Connect(tls), "s3cret-token");
  EXPECT_EQ(CodeOf([&] { anonymous.ListJobs(); }), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(right.ListJobs().jobs_size(), 0);
}

// --tls-client-ca: only clients with a certificate that CA signed get in.
TEST_F(ServiceExtras, MutualTlsRequiresAClientCertificateFromTheCa) {
  const std::string key = (dir_ / "key.pem").string(), cert = (dir_ / "cert.pem").string();
  const std::string client_key = (dir_ / "client-key.pem").string(),
                    client_cert = (dir_ / "client-cert.pem").string();
  const std::string other_key = (dir_ / "other-key.pem").string(),
                    other_cert = (dir_ / "other-cert.pem").string();
  if (!MakeSelfSignedCertificate(key, cert) ||
      !MakeSelfSignedCertificate(client_key, client_cert) ||
      !MakeSelfSignedCertificate(other_key, other_cert)) {
    GTEST_SKIP() << "openssl is not available";
  }
  StartDaemon(
      {"--workers", "1", "--tls-cert", cert, "--tls-key", key, "--tls-client-ca", client_cert});
  rpc::ConnectOptions options;
  options.address = daemon_->address();
  options.tls_ca_file = cert;
  rpc::MapBuilderClient without(rpc::Connect(options));
  EXPECT_EQ(CodeOf([&] { without.ListJobs(); }), grpc::StatusCode::UNAVAILABLE);
  options.tls_cert_file = other_cert;
  options.tls_key_file = other_key;
  rpc::MapBuilderClient stranger(rpc::Connect(options));
  EXPECT_EQ(CodeOf([&] { stranger.ListJobs(); }), grpc::StatusCode::UNAVAILABLE);
  options.tls_cert_file = client_cert;
  options.tls_key_file = client_key;
  rpc::MapBuilderClient known(rpc::Connect(options));
  EXPECT_EQ(known.ListJobs().jobs_size(), 0);
  EXPECT_THAT(daemon_->Log(), ::testing::HasSubstr("client certificates required"));
}

}  // namespace
}  // namespace boicp::test
