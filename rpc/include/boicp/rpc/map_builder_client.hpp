#pragma once
// A small synchronous client of boicp.v1.MapBuilder: upload (skipping bytes
// the daemon already holds), submit, watch, fetch results and export. Used
// by the demo client and the daemon's tests.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include <grpcpp/grpcpp.h>

#include "boicp/io/scan_source.hpp"
#include "boicp/v1/map_builder.grpc.pb.h"

namespace boicp::rpc {

namespace v1 = ::boicp::v1;

/// A call that ended with a status other than OK.
class RpcError : public std::runtime_error {
 public:
  RpcError(const std::string& rpc, const grpc::Status& status);
  grpc::StatusCode code() const { return code_; }
  /// The status message alone, without the rpc name and code.
  const std::string& detail() const { return detail_; }

 private:
  grpc::StatusCode code_;
  std::string detail_;
};

struct ConnectOptions {
  std::string address;                      // HOST:PORT
  std::string token;                        // bearer token; empty = none
  std::string tls_ca_file;                  // PEM roots; empty = plaintext
  std::string tls_cert_file, tls_key_file;  // client certificate (mutual TLS); empty = none
  int max_message_bytes = 4 << 20;
};

/// Throws std::runtime_error when the CA file cannot be read.
std::shared_ptr<grpc::Channel> Connect(const ConnectOptions& options);

class MapBuilderClient {
 public:
  explicit MapBuilderClient(std::shared_ptr<grpc::Channel> channel, std::string token = "");

  /// Adds the bearer token (if any) to a context for a raw stub call.
  void Authorize(grpc::ClientContext& context) const;
  v1::MapBuilder::Stub& stub() { return *stub_; }

  /// Deadline for each unary call (FindScans, SubmitBatch, GetJob, ListJobs,
  /// CancelJob, DeleteJob, GetResults), so that an unreachable daemon fails in seconds.
  /// Streams (upload, watch, export) never get one. 0 (the default) = none.
  void set_unary_timeout(std::chrono::milliseconds timeout) { unary_timeout_ = timeout; }

  /// Uploads a scan; when the daemon already holds these bytes only the
  /// metadata is sent (and the bytes after all if its copy turns out
  /// corrupted). metadata.size_bytes and sha256 are filled in here.
  v1::UploadScanResponse Upload(const std::string& bytes, v1::ScanMetadata metadata,
                                size_t chunk_bytes = 1 << 20);
  /// Reads the file and uploads it. Throws std::runtime_error when unreadable.
  v1::UploadScanResponse UploadFile(const std::string& path, const v1::ScanMetadata& metadata);
  /// Uploads a scan (metadata from ScanMetadataOf): its ScanUploadBytes.
  v1::UploadScanResponse UploadScan(const ScanSource& scan, const v1::ScanMetadata& metadata);

  v1::Job Submit(const v1::SubmitBatchRequest& request);
  v1::Job GetJob(const std::string& job_id);
  v1::Job Cancel(const std::string& job_id);
  v1::DeleteJobResponse Delete(const std::string& job_id);
  /// One page of jobs, newest first; page_size 0 = the daemon's default (50).
  v1::ListJobsResponse ListJobs(uint32_t page_size = 0, const std::string& page_token = "");
  /// Every result of the job, gathered page by page; `page_size` pairs (and
  /// poses) per GetResults call, 0 = the daemon's maximum (2000).
  v1::JobResults Results(const std::string& job_id, uint32_t page_size = 0);

  /// Follows WatchJob to its end and returns the job of the last event.
  /// Throws RpcError when the stream ends with an error status.
  v1::Job Watch(const std::string& job_id,
                const std::function<void(const v1::JobEvent&)>& on_event = {});

  /// Writes one export to `path`; returns the number of bytes. `drive` K
  /// >= 1: a trajectory of drive K alone (ExportRequest.drive). Throws
  /// RpcError, or std::runtime_error when the size does not match.
  uint64_t ExportToFile(const std::string& job_id, v1::ExportFormat format, const std::string& path,
                        uint32_t drive = 0);

 private:
  /// Authorize, plus the unary deadline when one is set.
  void PrepareUnary(grpc::ClientContext& context) const;

  std::unique_ptr<v1::MapBuilder::Stub> stub_;
  std::string token_;
  std::chrono::milliseconds unary_timeout_{0};
};

/// The bytes a scan is uploaded as: its file, or for a scan inside a bag the
/// binary PCD of its points (the format ScanMetadataOf declares). Throws
/// std::runtime_error when a file is unreadable, InputError when a bag's
/// scan does not load.
std::string ScanUploadBytes(const ScanSource& scan);

/// Lowercase hex SHA-256 of `bytes`, the scan id the daemon will assign.
std::string ScanId(const std::string& bytes);

}  // namespace boicp::rpc
