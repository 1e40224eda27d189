#pragma once
// Failures of the data directory itself, as opposed to bad requests or bugs.
// The RPC edge turns them into their own status codes (service_error.cpp).

#include <stdexcept>
#include <string>

namespace boicp::server {

/// The data directory refused a read or write: full, read-only, missing or
/// failing. Becomes FAILED_PRECONDITION: the request was fine, the disk is not.
/// `reply`, when given, is what a client is told instead of the message
/// (which the log keeps): without figures about the server, such as its free space.
class StorageError : public std::runtime_error {
 public:
  explicit StorageError(const std::string& message, const std::string& reply = "")
      : std::runtime_error(message), reply_(reply.empty() ? message : reply) {}
  const std::string& reply() const { return reply_; }

 private:
  std::string reply_;
};

/// A stored scan's bytes no longer hash to its id (or its file is gone).
/// Becomes DATA_LOSS; a job that meets one fails with this message.
class CorruptScanError : public std::runtime_error {
 public:
  explicit CorruptScanError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace boicp::server
