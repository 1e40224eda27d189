#include "upload_budget.hpp"

#include <string>

#include "service_error.hpp"

namespace boicp::server {

uint64_t UploadBudget::bytes_in_flight() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bytes_;
}

void UploadBudget::Reserve(uint64_t bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (uploads_ >= max_uploads_) {
    throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                       std::to_string(uploads_) + " uploads are in flight, this daemon's limit (" +
                           "--max-concurrent-uploads " + std::to_string(max_uploads_) +
                           "); retry when one ends");
  }
  if (bytes > max_bytes_ - bytes_) {
    throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                       "uploads in flight already announce " + std::to_string(bytes_) + " bytes; " +
                           std::to_string(bytes) + " more is over this daemon's " + "limit of " +
                           std::to_string(max_bytes_) +
                           " (--max-upload-bytes-in-flight); retry when one ends");
  }
  ++uploads_;
  bytes_ += bytes;
}

void UploadBudget::Release(uint64_t bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  --uploads_;
  bytes_ -= bytes;
}

}  // namespace boicp::server
