#include "server_fixture.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "../support/demo_sequence.hpp"

namespace boicp::test {

v1::SubmitBatchRequest QuickBatch(const std::vector<std::string>& scan_ids, uint64_t seed) {
  v1::SubmitBatchRequest request;
  for (const std::string& id : scan_ids) request.add_scan_ids(id);
  request.mutable_pairing()->set_mode(v1::PairingPolicy::MODE_CONSECUTIVE);
  v1::RegistrationConfig& config = *request.mutable_config();
  config.set_preset("A");
  config.set_random_samples(4);
  config.set_iterations(4);
  config.set_seed(seed);
  config.mutable_rotation_bounds()->set_x(0.2);
  config.mutable_rotation_bounds()->set_y(0.2);
  config.mutable_rotation_bounds()->set_z(M_PI);
  request.mutable_map()->set_resolution(0.3);
  request.mutable_map()->set_max_range(30.0);
  request.set_label("test");
  return request;
}

v1::SubmitBatchRequest SlowBatch(const std::vector<std::string>& scan_ids) {
  v1::SubmitBatchRequest request = QuickBatch(scan_ids);
  request.mutable_config()->set_preset("C");
  request.mutable_config()->clear_random_samples();
  request.mutable_config()->clear_iterations();
  // The fixed budget, so that the search runs in full: the ladder's first
  // rung answers these scans in a fraction of a second.
  request.mutable_config()->set_budget("fixed");
  return request;
}

grpc::Status RawUpload(rpc::MapBuilderClient& client, const v1::ScanMetadata& metadata,
                       const std::vector<std::string>& chunks, const std::string& token) {
  grpc::ClientContext context;
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
  v1::UploadScanResponse response;
  auto writer = client.stub().UploadScan(&context, &response);
  v1::UploadScanRequest message;
  *message.mutable_metadata() = metadata;
  bool open = writer->Write(message);
  for (const std::string& chunk : chunks) {
    if (!open) break;
    message.set_chunk(chunk);
    open = writer->Write(message);
  }
  writer->WritesDone();
  return writer->Finish();
}

std::string StarScan(int seed) {
  constexpr int kRays = 100;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  std::string text;
  char line[96];
  for (int r = 0; r < kRays; ++r) {
    const double z = 1.0 - 2.0 * (r + 0.5) / kRays;
    const double radius = std::sqrt(1.0 - z * z);
    const double angle = golden * r + 0.01 * seed;
    for (double d = 1.0; d <= 100.0; d += 0.3) {
      std::snprintf(line, sizeof line, "%.3f %.3f %.3f\n", d * radius * std::cos(angle),
                    d * radius * std::sin(angle), d * z);
      text += line;
    }
  }
  return text;
}

v1::ScanMetadata Meta(v1::ScanFormat format, size_t size) {
  v1::ScanMetadata metadata;
  metadata.set_format(format);
  metadata.set_size_bytes(size);
  return metadata;
}

std::vector<std::string> MissingScans(rpc::MapBuilderClient& client,
                                      const std::vector<std::string>& ids) {
  grpc::ClientContext context;
  client.Authorize(context);
  v1::FindScansRequest request;
  for (const std::string& id : ids) request.add_scan_ids(id);
  v1::FindScansResponse response;
  EXPECT_TRUE(client.stub().FindScans(&context, request, &response).ok());
  return {response.missing().begin(), response.missing().end()};
}

void ServerTest::SetUp() {
  dir_ = std::filesystem::temp_directory_path() /
         ("boicpd_test_" + std::to_string(::getpid()) + "_" +
          ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(dir_);
  std::filesystem::create_directories(dir_);
  data_dir_ = dir_ / "data";
}

void ServerTest::TearDown() {
  if (daemon_ && HasFailure()) {
    std::cerr << "---- boicpd log ----\n" << daemon_->Log() << "--------------------\n";
  }
  daemon_.reset();
  std::filesystem::remove_all(dir_);
}

void ServerTest::StartDaemon(const std::vector<std::string>& args) {
  daemon_.reset();
  std::vector<std::string> all = {"--data-dir", data_dir_.string()};
  all.insert(all.end(), args.begin(), args.end());
  daemon_ = std::make_unique<DaemonProcess>(
      all, (dir_ / ("boicpd." + std::to_string(starts_++) + ".log")).string());
}

rpc::MapBuilderClient ServerTest::Client(const std::string& token) const {
  rpc::ConnectOptions options;
  options.address = daemon_->address();
  return rpc::MapBuilderClient(rpc::Connect(options), token);
}

std::vector<std::string> ServerTest::UploadDrive(rpc::MapBuilderClient& client, int n,
                                                 uint64_t seed, std::vector<Transform>* truth) {
  std::vector<std::string> ids;
  for (const auto& scan : test::MakeDemoSequence(n, seed)) {
    v1::ScanMetadata metadata;
    metadata.set_format(v1::SCAN_FORMAT_KITTI_BIN);
    ids.push_back(client.Upload(scan.kitti_bytes, metadata).scan_id());
    if (truth) truth->push_back(scan.T_world_scan);
  }
  return ids;
}

std::string ServerTest::SubmitLongFusion(rpc::MapBuilderClient& client) {
  std::vector<std::string> ids;
  for (int seed = 0; seed < 2; ++seed) {
    const std::string scan = StarScan(seed);
    ids.push_back(client.Upload(scan, Meta(v1::SCAN_FORMAT_XYZ, scan.size())).scan_id());
  }
  v1::SubmitBatchRequest request = QuickBatch(ids);
  request.mutable_map()->set_resolution(0.01);
  request.mutable_map()->set_max_range(150.0);
  const std::string job_id = client.Submit(request).job_id();
  const v1::Job fusing = PollJob(
      client, job_id, [](const v1::Job& j) { return j.stage() == "fusing"; }, 300);
  EXPECT_EQ(fusing.stage(), "fusing") << fusing.error();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  return job_id;
}

v1::Job ServerTest::PollJob(rpc::MapBuilderClient& client, const std::string& job_id,
                            const std::function<bool(const v1::Job&)>& done, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  v1::Job job = client.GetJob(job_id);
  while (!done(job) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    job = client.GetJob(job_id);
  }
  return job;
}

}  // namespace boicp::test
