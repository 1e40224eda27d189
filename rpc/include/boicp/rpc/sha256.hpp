#pragma once
// Incremental SHA-256 (OpenSSL), the content hash that names stored scans.

#include <cstddef>
#include <memory>
#include <string>

namespace boicp::rpc {

class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  void Update(const void* data, size_t size);
  /// Lowercase hex of the digest. Ends the hash; call once.
  std::string HexDigest();

 private:
  struct Context;
  std::unique_ptr<Context> context_;
};

/// True for exactly 64 lowercase hex digits, the form of every scan id.
bool IsSha256Hex(const std::string& text);

}  // namespace boicp::rpc
