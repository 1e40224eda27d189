#include "auth.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include <grpcpp/security/server_credentials.h>

#include "boicp/util/text.hpp"

namespace boicp::server {
namespace {

std::string ReadFile(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(std::string(what) + " " + path + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Compares in time independent of where the strings differ.
bool SameSecret(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (size_t i = 0; i < a.size(); ++i) {
    diff |= static_cast<unsigned char>(a[i] ^ (i < b.size() ? b[i] : 0));
  }
  return diff == 0;
}

}  // namespace

std::vector<std::string> BearerAuth::TokenFileWarnings(const std::string& path) {
  struct stat status {};
  if (stat(path.c_str(), &status) != 0) return {};
  std::vector<std::string> warnings;
  if ((status.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(status.st_mode & 07777));
    warnings.push_back("auth token file " + path + " is open to group or others (mode " + mode +
                       "): chmod 600 " + path);
  }
  if (status.st_uid != geteuid()) {
    warnings.push_back("auth token file " + path + " is owned by uid " +
                       std::to_string(status.st_uid) + ", not by this daemon's user (uid " +
                       std::to_string(geteuid()) + "): another user can change the token");
  }
  return warnings;
}

BearerAuth BearerAuth::FromFile(const std::string& path) {
  BearerAuth auth;
  auth.token_ = Trim(ReadFile(path, "auth token file"));
  if (auth.token_->empty()) throw std::runtime_error("auth token file " + path + " is empty");
  return auth;
}

grpc::Status BearerAuth::Check(const grpc::ServerContextBase& context) const {
  if (!token_) return grpc::Status::OK;
  const auto& metadata = context.client_metadata();
  const auto found = metadata.find("authorization");
  if (found == metadata.end()) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "missing 'authorization: Bearer <token>' metadata");
  }
  const std::string value(found->second.data(), found->second.size());
  // RFC 6750 takes the scheme name in any case ("bearer" is "Bearer").
  const std::string scheme = "bearer ";
  if (LowerCase(value.substr(0, scheme.size())) != scheme ||
      !SameSecret(value.substr(scheme.size()), *token_)) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "invalid bearer token");
  }
  return grpc::Status::OK;
}

std::shared_ptr<grpc::ServerCredentials> MakeServerCredentials(const std::string& cert_path,
                                                               const std::string& key_path,
                                                               const std::string& client_ca_path) {
  if (cert_path.empty() && key_path.empty() && client_ca_path.empty()) {
    return grpc::InsecureServerCredentials();
  }
  if (cert_path.empty() || key_path.empty()) {
    throw std::runtime_error("TLS needs both --tls-cert and --tls-key");
  }
  grpc::SslServerCredentialsOptions options(
      client_ca_path.empty() ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                             : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  if (!client_ca_path.empty()) options.pem_root_certs = ReadFile(client_ca_path, "TLS client CA");
  options.pem_key_cert_pairs.push_back(
      {ReadFile(key_path, "TLS key"), ReadFile(cert_path, "TLS certificate")});
  return grpc::SslServerCredentials(options);
}

}  // namespace boicp::server
