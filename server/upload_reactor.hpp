#pragma once
// UploadScan: metadata first, then the bytes in chunks, written to a temp
// file and hashed as they arrive. At the end the scan is parsed with the
// core loaders (so a malformed scan is refused at upload, not mid-batch),
// then renamed to its hash and recorded, on the daemon's upload threads
// (ServiceDeps::upload_threads), never on a gRPC thread. A scan's metadata
// is written once: stored bytes sent or named again with metadata a batch
// would read differently are refused (FAILED_PRECONDITION,
// scan_metadata_once.hpp).
// Refused (FAILED_PRECONDITION) while the data directory cannot take the
// announced bytes with those of the other uploads in flight, and
// (RESOURCE_EXHAUSTED) over the upload budget, which an upload reusing
// stored bytes is charged their size in too. An upload that goes silent or
// sends slower than the minimum rate ends (see UploadWatchdog), so a slot is
// never held for long by a slow client.

#include <fstream>
#include <mutex>
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
  /// Finishes at once with `auth` unless it is OK; otherwise the upload ends
  /// with DEADLINE_EXCEEDED (or is cancelled) once it sends nothing for the
  /// idle timeout or falls behind the minimum rate (deps.upload_watchdog).
  /// An upload naming a stored hash is answered right after its metadata.
  UploadReactor(const ServiceDeps& deps, grpc::CallbackServerContext* context,
                ::boicp::v1::UploadScanResponse* response, const grpc::Status& auth);

  void OnReadDone(bool ok) override;
  void OnDone() override;

 private:
  /// Takes in the message just read (or, when !ok, ends the upload), then
  /// reads the next or finishes.
  void HandleRead(bool ok);
  void Accept(const ::boicp::v1::UploadScanRequest& request);
  void AcceptMetadata(const ::boicp::v1::ScanMetadata& metadata);
  void AcceptChunk(const std::string& bytes);
  void Complete();
  /// Answers an upload naming a stored hash with the stored record: its
  /// metadata, checked in ReuseStoredCopy, is what the client sent.
  void AnswerFromStoredCopy();
  /// Frees the upload's slot and bytes in the budget, then finishes: a client
  /// that has heard this upload end is never refused because of it.
  void FinishUpload(const grpc::Status& status);
  /// Whether the client may skip the bytes: the store holds an intact copy
  /// of the hash it names. The check re-reads (and the upload's end may
  /// re-parse) the stored bytes on this thread, so it first takes a slot and
  /// the stored size in the upload budget, as an upload of those bytes would:
  /// a few bytes of metadata cannot start unbounded work.
  bool ReuseStoredCopy(const ::boicp::v1::ScanMetadata& metadata);
  /// Verifies the stored copy a client wants to reuse; false (and the reason
  /// in corruption_) when it failed its hash check.
  bool StoredCopyIntact(const std::string& scan_id);

  const ServiceDeps& deps_;
  // The steps run one at a time, on gRPC's threads or the upload threads;
  // gRPC orders them inside its library, where ThreadSanitizer cannot see,
  // so the mutex hands each step's state to the next where it can.
  std::mutex steps_;
  grpc::CallbackServerContext* context_;  // polled for a cancel while decoding waits
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
  uint64_t watch_id_ = 0;  // in deps_.upload_watchdog; 0 = not timed
};

}  // namespace boicp::server
