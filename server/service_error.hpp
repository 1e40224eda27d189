#pragma once
// A failure that maps to one gRPC status code. The daemon throws it where the
// code is known and turns it into a grpc::Status at the RPC edge.

#include <stdexcept>
#include <string>

#include <grpcpp/support/status.h>

namespace boicp::server {

class ServiceError : public std::runtime_error {
 public:
  ServiceError(grpc::StatusCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  grpc::StatusCode code() const { return code_; }

 private:
  grpc::StatusCode code_;
};

/// `text` with every absolute path shortened to ".../" and its last name: a
/// client learns which file, not where the daemon keeps its data.
std::string WithoutServerPaths(const std::string& text);

/// Converts the exception being handled (call only inside a catch block):
/// ServiceError keeps its code, boicp::InputError becomes INVALID_ARGUMENT,
/// LimitExceeded RESOURCE_EXHAUSTED, StorageError FAILED_PRECONDITION,
/// CorruptScanError DATA_LOSS, anything else INTERNAL, logged with `rpc` so
/// that a bug is visible. Replies carry WithoutServerPaths of the message;
/// the log keeps it whole.
grpc::Status StatusFromCurrentException(const char* rpc);

/// Runs `handler` and converts whatever it throws with StatusFromCurrentException.
template <typename Handler>
grpc::Status GuardRpc(const char* rpc, Handler&& handler) {
  try {
    return handler();
  } catch (...) {
    return StatusFromCurrentException(rpc);
  }
}

}  // namespace boicp::server
