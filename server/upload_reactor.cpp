#include "upload_reactor.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "scan_integrity.hpp"
#include "scan_metadata_once.hpp"
#include "service.hpp"
#include "service_error.hpp"
#include "storage_check.hpp"
#include "storage_errors.hpp"

namespace boicp::server {
namespace {

// Loader messages name the file; the client knows it as its upload.
std::string WithoutPath(std::string message, const std::string& path) {
  for (size_t at = message.find(path); at != std::string::npos; at = message.find(path)) {
    message.replace(at, path.size(), "uploaded scan");
  }
  return message;
}

void RequirePointLimit(uint64_t points, uint64_t limit) {
  if (points > limit) {
    throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                       "scan has " + std::to_string(points) +
                           " points, over this daemon's limit of " + std::to_string(limit) +
                           " (--max-scan-points)");
  }
}

// The loaders refuse a scan over the limit from its header, before they
// allocate its points. With a decode budget the load waits, on an upload
// thread, until the scan's decoding bound fits beside the other decodes (the
// returned cloud holds its share); a scan that could never fit is refused.
LoadedCloud LoadUploadedScan(const std::string& path, const v1::ScanMetadata& metadata,
                             const ServiceDeps& deps, grpc::CallbackServerContext* context) {
  LoadOptions options = rpc::LoadOptionsFromMetadata(metadata);
  options.max_points = deps.max_scan_points;
  options.decode_budget = deps.decode_budget;
  // Polled only while the load waits, so its first call marks the wait.
  options.decode_stop = [context, logged = false]() mutable {
    if (!logged) {
      spdlog::info("an upload waits for decoding memory (--max-decode-mb)");
      logged = true;
    }
    return context->IsCancelled();
  };
  try {
    return LoadPointCloud(path, options);
  } catch (const PointLimitError& e) {
    RequirePointLimit(e.points(), e.limit());
    throw;
  } catch (const InputError& e) {
    throw InputError(WithoutPath(e.what(), path));
  } catch (const LimitExceeded& e) {
    throw LimitExceeded(WithoutPath(e.what(), path));
  } catch (const Cancelled&) {
    throw ServiceError(grpc::StatusCode::UNAVAILABLE,
                       "the upload stopped waiting for decoding memory (--max-decode-mb): "
                       "it was cancelled or boicpd is shutting down");
  }
}

}  // namespace

UploadReactor::UploadReactor(const ServiceDeps& deps, grpc::CallbackServerContext* context,
                             v1::UploadScanResponse* response, const grpc::Status& auth)
    : deps_(deps), context_(context), response_(response) {
  if (!auth.ok()) {
    FinishUpload(auth);
    return;
  }
  watch_id_ = deps_.upload_watchdog.Enter(context);
  StartRead(&request_);
}

void UploadReactor::OnReadDone(bool ok) {
  if (ok) {
    const std::string over = deps_.upload_watchdog.Touch(watch_id_, request_.chunk().size());
    if (!over.empty()) {
      spdlog::warn("{}: ended", over);
      FinishUpload(grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, over));
      return;
    }
  } else {
    const std::string cancelled = deps_.upload_watchdog.CancelReason(watch_id_);
    if (!cancelled.empty()) {
      FinishUpload(grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, cancelled));
      return;
    }
    deps_.upload_watchdog.Sent(watch_id_);
  }
  // A chunk is appended and hashed here. Metadata (which may re-hash a
  // stored copy) and the end (waiting for decoding memory, parsing, fsync)
  // go to the upload threads: a gRPC thread they held would be one fewer
  // for every other call, and enough of them would stall the daemon.
  if (ok && request_.payload_case() == v1::UploadScanRequest::kChunk) {
    HandleRead(ok);
  } else {
    deps_.upload_threads.Submit([this, ok] { HandleRead(ok); });
  }
}

void UploadReactor::HandleRead(bool ok) {
  grpc::Status status;
  {
    std::lock_guard<std::mutex> lock(steps_);
    status = GuardRpc("UploadScan", [&] {
      if (!ok) {
        Complete();
      } else {
        Accept(request_);
        if (known_) {
          // The daemon holds the bytes the metadata names: answer now rather
          // than hold a slot while the client sends bytes that would not be read.
          deps_.upload_watchdog.Sent(watch_id_);
          Complete();
        }
      }
      return grpc::Status::OK;
    });
  }
  if (status.ok() && ok && !known_) {
    StartRead(&request_);
  } else {
    FinishUpload(status);
  }
}

void UploadReactor::FinishUpload(const grpc::Status& status) {
  ticket_.reset();
  Finish(status);
}

void UploadReactor::OnDone() {
  {
    std::lock_guard<std::mutex> lock(steps_);
    if (watch_id_ != 0) deps_.upload_watchdog.Leave(watch_id_);
    if (temp_.is_open()) temp_.close();
    if (!temp_path_.empty()) {
      std::error_code ignored;
      std::filesystem::remove(temp_path_, ignored);
    }
  }
  delete this;
}

void UploadReactor::Accept(const v1::UploadScanRequest& request) {
  switch (request.payload_case()) {
    case v1::UploadScanRequest::kMetadata:
      AcceptMetadata(request.metadata());
      return;
    case v1::UploadScanRequest::kChunk:
      AcceptChunk(request.chunk());
      return;
    default:
      throw InputError("an upload message carries metadata or a chunk");
  }
}

void UploadReactor::AcceptMetadata(const v1::ScanMetadata& metadata) {
  if (metadata_) throw InputError("metadata may only be sent once, first");
  rpc::ValidateScanMetadata(metadata);
  known_ = ReuseStoredCopy(metadata);
  if (!known_) {
    if (metadata.size_bytes() == 0) {
      throw InputError("metadata.size_bytes is required (the number of bytes that follow)");
    }
    if (metadata.size_bytes() > deps_.max_scan_bytes) {
      throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                         "scan of " + std::to_string(metadata.size_bytes()) +
                             " bytes is over this daemon's limit of " +
                             std::to_string(deps_.max_scan_bytes) + " (--max-scan-bytes)");
    }
    ticket_.reset();  // a stored copy that failed its check: the bytes come now
    // The other uploads in flight still have their announced bytes to write.
    RequireStorage(deps_.data_dir, deps_.min_free_bytes,
                   deps_.uploads.bytes_in_flight() + metadata.size_bytes());
    RequireStoredQuota(deps_.data_dir, deps_.max_stored_bytes,
                       deps_.uploads.bytes_in_flight() + metadata.size_bytes());
    ticket_.emplace(deps_.uploads, metadata.size_bytes());
    temp_path_ = deps_.data_dir.NewTempPath();
    temp_.open(temp_path_, std::ios::binary | std::ios::trunc);
    if (!temp_) {
      throw StorageError("cannot create " + temp_path_ + " (" + std::strerror(errno) + ")");
    }
  }
  metadata_ = metadata;
}

bool UploadReactor::ReuseStoredCopy(const v1::ScanMetadata& metadata) {
  if (metadata.sha256().empty()) return false;
  const std::optional<StoredScan> stored = deps_.store.GetScan(metadata.sha256());
  if (!stored) return false;
  // Refused before any work on the bytes: a copy this client would decode
  // otherwise is not worth hashing for it. Another context (sensor origin,
  // prior pose, timestamp) is a reuse: the stored record stays as it is.
  RequireStoredMetadata(metadata.sha256(), stored->metadata, metadata);
  if (!deps_.data_dir.HasScanFile(metadata.sha256())) return false;
  RequireStorage(deps_.data_dir, deps_.min_free_bytes, deps_.uploads.bytes_in_flight());
  deps_.data_dir.TouchScan(metadata.sha256());
  ticket_.emplace(deps_.uploads, stored->metadata.size_bytes());
  return StoredCopyIntact(metadata.sha256());
}

bool UploadReactor::StoredCopyIntact(const std::string& scan_id) {
  try {
    VerifyStoredScan(deps_.data_dir, scan_id);
    return true;
  } catch (const CorruptScanError& e) {
    corruption_ = e.what();  // the stored copy is gone; the bytes must come again
    return false;
  }
}

void UploadReactor::AcceptChunk(const std::string& bytes) {
  if (!metadata_) throw InputError("the first upload message must carry metadata");
  if (received_ + bytes.size() > metadata_->size_bytes()) {
    throw InputError("more bytes than metadata.size_bytes (" +
                     std::to_string(metadata_->size_bytes()) + ")");
  }
  temp_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!temp_) {
    throw StorageError("writing " + temp_path_ + " failed (" + std::strerror(errno) + ")");
  }
  hash_.Update(bytes.data(), bytes.size());
  received_ += bytes.size();
}

void UploadReactor::Complete() {
  if (!metadata_) throw InputError("empty upload: send metadata, then the bytes");
  if (known_) {
    AnswerFromStoredCopy();
    return;
  }
  v1::ScanMetadata metadata = *metadata_;
  if (received_ == 0 && !corruption_.empty()) {
    throw ServiceError(grpc::StatusCode::DATA_LOSS, corruption_ + "; send the bytes with it");
  }
  if (received_ != metadata.size_bytes()) {
    throw InputError("received " + std::to_string(received_) + " bytes, metadata.size_bytes says " +
                     std::to_string(metadata.size_bytes()));
  }
  temp_.close();
  if (!temp_) {
    throw StorageError("writing " + temp_path_ + " failed (" + std::strerror(errno) + ")");
  }
  const std::string id = hash_.HexDigest();
  if (!metadata.sha256().empty() && metadata.sha256() != id) {
    throw InputError("metadata.sha256 does not match the bytes received (got " + id + ")");
  }
  // Bytes sent with another decoding than the stored record's are refused
  // before they are parsed, as a metadata-only upload would be.
  if (const std::optional<StoredScan> stored = deps_.store.GetScan(id)) {
    RequireStoredMetadata(id, stored->metadata, metadata);
  }
  const LoadedCloud cloud = LoadUploadedScan(temp_path_, metadata, deps_, context_);
  const bool present = deps_.data_dir.HasScanFile(id);
  if (!present) {
    deps_.data_dir.CommitScan(temp_path_, id);
    temp_path_.clear();
  } else {
    deps_.data_dir.TouchScan(id);  // uploaded again: its grace starts again
  }
  metadata.set_sha256(id);
  // Another upload of these bytes may have stored its record since the
  // check above: the first record (and its context) stays, and this one must
  // decode the bytes as it does.
  const StoredScan kept =
      deps_.store.PutScan(metadata, cloud.points.size(), ProfileRanges(cloud.points));
  RequireStoredMetadata(id, kept.metadata, metadata);
  response_->set_scan_id(id);
  response_->set_already_present(present);
  response_->set_num_points(kept.num_points);
  response_->set_size_bytes(metadata.size_bytes());
  spdlog::info("scan {} stored: {} bytes, {} points", id.substr(0, 12), metadata.size_bytes(),
               kept.num_points);
}

void UploadReactor::AnswerFromStoredCopy() {
  const std::string& id = metadata_->sha256();
  const std::optional<StoredScan> stored = deps_.store.GetScan(id);
  if (!stored) {
    throw ServiceError(grpc::StatusCode::FAILED_PRECONDITION,
                       "scan " + id + " was deleted, unused, meanwhile (upload it again)");
  }
  uint64_t points = stored->num_points;
  if (stored->ranges.empty()) {
    // Stored before range profiles were: profiled now, read as stored.
    const LoadedCloud cloud =
        LoadUploadedScan(deps_.data_dir.ScanPath(id), stored->metadata, deps_, context_);
    points = deps_.store.PutScan(stored->metadata, cloud.points.size(), ProfileRanges(cloud.points))
                 .num_points;
  }
  RequirePointLimit(points, deps_.max_scan_points);
  response_->set_scan_id(id);
  response_->set_already_present(true);
  response_->set_num_points(points);
  response_->set_size_bytes(stored->metadata.size_bytes());
  spdlog::info("scan {} already stored; reused with its stored metadata", id.substr(0, 12));
}

}  // namespace boicp::server
