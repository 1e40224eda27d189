#pragma once
// What every daemon test shares: a temporary folder, a daemon process on a
// free loopback port, a client, and quick batches of a generated drive.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "boicp/rpc/map_builder_client.hpp"
#include "boicp/util/types.hpp"
#include "daemon_process.hpp"

namespace boicp::test {

namespace v1 = ::boicp::v1;

/// Settings that keep a generated-drive batch to about a second a pair on
/// this machine: preset A cut to 4 + 4 evaluations per stage, ground-vehicle
/// rotation bounds. The scans overlap so much that this is still exact.
v1::SubmitBatchRequest QuickBatch(const std::vector<std::string>& scan_ids, uint64_t seed = 3);

/// QuickBatch with the full preset C search (budget fixed): seconds a pair,
/// so a test can act while it runs.
v1::SubmitBatchRequest SlowBatch(const std::vector<std::string>& scan_ids);

/// Uploads raw messages: `metadata`, then `chunks` (stopping at the first
/// refused write). Returns the final status.
grpc::Status RawUpload(rpc::MapBuilderClient& client, const v1::ScanMetadata& metadata,
                       const std::vector<std::string>& chunks, const std::string& token = "");

v1::ScanMetadata Meta(v1::ScanFormat format, size_t size);

/// An XYZ scan whose fusion at 1 cm leaves takes seconds yet builds a small
/// tree: points every 30 cm out to 100 m on 100 rays from the sensor. Each
/// point casts a ray of up to 10,000 cells, and all of them share the cells
/// of 100 lines. `seed` turns the star, so that two scans differ.
std::string StarScan(int seed);

/// The ids among `ids` that FindScans reports missing.
std::vector<std::string> MissingScans(rpc::MapBuilderClient& client,
                                      const std::vector<std::string>& ids);

/// How a client call ended: OK when it returned, else the RpcError's code and
/// message (without the rpc name).
template <typename Call>
grpc::Status StatusOf(Call&& call) {
  try {
    call();
  } catch (const rpc::RpcError& e) {
    return grpc::Status(e.code(), e.detail());
  }
  return grpc::Status::OK;
}

template <typename Call>
grpc::StatusCode CodeOf(Call&& call) {
  return StatusOf(std::forward<Call>(call)).error_code();
}

class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;

  /// Starts (or restarts) the daemon on data_dir_ with `args` after
  /// --data-dir. Default workers: 2, one registration thread.
  void StartDaemon(const std::vector<std::string>& args = {"--workers", "2"});
  void StopDaemon() { daemon_.reset(); }

  rpc::MapBuilderClient Client(const std::string& token = "") const;

  /// Uploads a generated drive of `n` scans; returns their ids and, in
  /// `truth`, their poses.
  std::vector<std::string> UploadDrive(rpc::MapBuilderClient& client, int n, uint64_t seed,
                                       std::vector<Transform>* truth = nullptr);

  /// Submits a batch of two star scans at 1 cm leaves and waits until fusion
  /// has begun its first scan: "fusing" is published just before, and a
  /// moment later the first between-scans check has passed, seconds before
  /// the scan ends. Returns the job's id.
  std::string SubmitLongFusion(rpc::MapBuilderClient& client);

  /// Polls GetJob every 50 ms until `done(job)` or `timeout_s`; returns the last job.
  v1::Job PollJob(rpc::MapBuilderClient& client, const std::string& job_id,
                  const std::function<bool(const v1::Job&)>& done, double timeout_s);

  std::filesystem::path dir_;
  std::filesystem::path data_dir_;  // dir_/data unless a test points it elsewhere
  std::unique_ptr<DaemonProcess> daemon_;
  int starts_ = 0;
};

}  // namespace boicp::test
