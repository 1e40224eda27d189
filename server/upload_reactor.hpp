#pragma once
// UploadScan: metadata first, then the bytes in chunks, written to a temp
// file and hashed as they arrive. At the end the scan is parsed with the
// core loaders (so a malformed scan is refused at upload, not mid-batch),
// then renamed to its hash and recorded. Refused (FAILED_PRECONDITION) while
// the data directory cannot take the announced bytes with those of the other
// uploads in flight, and (RESOURCE_EXHAUSTED) over the upload budget.

#include <fstream>
#include <optional>
#include <string>

#include <grpcpp/support/server_callback.h>

#include "boicp/rpc/sha256.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "upload_budget.hpp"

namespace boicp::server {

struct ServiceDeps;

class UploadReactor : public grpc::ServerReadReactor<::boicp::v1::UploadScanRequest> {
 public:
  /// Finishes at once with `auth` unless it is OK.
  UploadReactor(const ServiceDeps& deps, ::boicp::v1::UploadScanResponse* response,
                const grpc::Status& auth);

  void OnReadDone(bool ok) override;
  void OnDone() override;

 private:
  void Accept(const ::boicp::v1::UploadScanRequest& request);
  void AcceptMetadata(const ::boicp::v1::ScanMetadata& metadata);
  void AcceptChunk(const std::string& bytes);
  void Complete();
  /// Frees the upload's slot and bytes in the budget, then finishes: a client
  /// that has heard this upload end is never refused because of it.
  void FinishUpload(const grpc::Status& status);
  /// Verifies the stored copy a client wants to reuse; false (and the reason
  /// in corruption_) when it failed its hash check.
  bool StoredCopyIntact(const std::string& scan_id);

  const ServiceDeps& deps_;
  ::boicp::v1::UploadScanResponse* response_;
  ::boicp::v1::UploadScanRequest request_;
  std::optional<::boicp::v1::ScanMetadata> metadata_;
  std::optional<UploadBudget::Ticket> ticket_;
  bool known_ = false;      // the client named a hash the store holds: bytes are not needed
  std::string corruption_;  // the stored copy of the named hash failed its check
  std::string temp_path_;
  std::ofstream temp_;
  rpc::Sha256 hash_;
  uint64_t received_ = 0;
};

}  // namespace boicp::server
