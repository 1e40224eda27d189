#pragma once
// Optional bearer-token authentication and TLS credentials.

#include <memory>
#include <optional>
#include <string>
#include <vector>

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

  /// What is unsafe about the token file at `path`, one line each, naming
  /// the fix: group or others may read it, or another user owns it. Empty
  /// when it is safe or cannot be examined (FromFile then says why).
  static std::vector<std::string> TokenFileWarnings(const std::string& path);

  bool enabled() const { return token_.has_value(); }

  /// OK, or UNAUTHENTICATED with a message saying what was missing. The
  /// scheme name ("Bearer") is matched case-insensitively (RFC 6750).
  grpc::Status Check(const grpc::ServerContextBase& context) const;

 private:
  std::optional<std::string> token_;
};

/// TLS credentials from PEM files, or insecure ones when every path is
/// empty. With `client_ca_path`, clients must present a certificate that CA
/// signed (mutual TLS). Throws std::runtime_error for an unreadable file or
/// when the certificate or its key is missing.
std::shared_ptr<grpc::ServerCredentials> MakeServerCredentials(
    const std::string& cert_path, const std::string& key_path,
    const std::string& client_ca_path = "");

}  // namespace boicp::server
