#pragma once
// Optional bearer-token authentication and TLS credentials.

#include <memory>
#include <optional>
#include <string>

#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server_context.h>

namespace boicp::server {

/// Checks the "authorization: Bearer <token>" metadata of every call when a
/// token is configured; without one every call passes.
class BearerAuth {
 public:
  /// No token: authentication is off.
  BearerAuth() = default;
  /// Reads the token from a file (surrounding whitespace ignored). Throws
  /// std::runtime_error when the file is unreadable or empty.
  static BearerAuth FromFile(const std::string& path);

  bool enabled() const { return token_.has_value(); }

  /// OK, or UNAUTHENTICATED with a message saying what was missing.
  grpc::Status Check(const grpc::ServerContextBase& context) const;

 private:
  std::optional<std::string> token_;
};

/// TLS credentials from PEM files, or insecure ones when both paths are
/// empty. Throws std::runtime_error for an unreadable file or when only one
/// of the two is given.
std::shared_ptr<grpc::ServerCredentials> MakeServerCredentials(const std::string& cert_path,
                                                               const std::string& key_path);

}  // namespace boicp::server
