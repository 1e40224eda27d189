#pragma once
// Failures of the data directory itself, as opposed to bad requests or bugs.
// The RPC edge turns them into their own status codes (service_error.cpp).

#include <stdexcept>
#include <string>

namespace boicp::server {

/// The data directory refused a read or write: full, read-only, missing or
/// failing. Becomes FAILED_PRECONDITION: the request was fine, the disk is not.
class StorageError : public std::runtime_error {
 public:
  explicit StorageError(const std::string& message) : std::runtime_error(message) {}
};

/// A stored scan's bytes no longer hash to its id (or its file is gone).
/// Becomes DATA_LOSS; a job that meets one fails with this message.
class CorruptScanError : public std::runtime_error {
 public:
  explicit CorruptScanError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace boicp::server
