#include "scan_integrity.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include <spdlog/spdlog.h>

#include "boicp/rpc/sha256.hpp"
#include "storage_errors.hpp"

namespace boicp::server {
namespace {

constexpr size_t kReadBytes = 1 << 20;

// Closes the descriptor on every path out.
struct FileDescriptor {
  int fd;
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

void VerifyStoredScan(const DataDir& dir, const std::string& scan_id) {
  const std::string path = dir.ScanPath(scan_id);
  const std::string aside = path + ".corrupt";
  const FileDescriptor file{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
  if (file.fd < 0) {
    const int error = errno;
    if (error == ENOENT && ::access(aside.c_str(), F_OK) == 0) {
      throw CorruptScanError("scan " + scan_id + ": sha256 mismatch found earlier; its file was " +
                             "moved to " + aside + " (upload the scan again)");
    }
    if (error == ENOENT) {
      throw CorruptScanError("scan " + scan_id + ": its file " + path +
                             " is missing from the data directory (upload the scan again)");
    }
    throw StorageError("scan " + scan_id + ": cannot open " + path + " (" + std::strerror(error) +
                       ")");
  }
  rpc::Sha256 hash;
  std::vector<char> buffer(kReadBytes);
  for (;;) {
    const ssize_t got = ::read(file.fd, buffer.data(), buffer.size());
    if (got == 0) break;
    if (got < 0) {
      if (errno == EINTR) continue;
      throw StorageError("scan " + scan_id + ": cannot read " + path + " (" + std::strerror(errno) +
                         ")");
    }
    hash.Update(buffer.data(), static_cast<size_t>(got));
  }
  const std::string actual = hash.HexDigest();
  if (actual == scan_id) return;

  // Move aside exactly the file that was hashed: if a fresh upload of the
  // scan replaced it meanwhile, the path now holds good bytes.
  struct stat hashed {
  }, current{};
  const bool same_file = ::fstat(file.fd, &hashed) == 0 && ::stat(path.c_str(), &current) == 0 &&
                         hashed.st_dev == current.st_dev && hashed.st_ino == current.st_ino;
  const bool moved = same_file && std::rename(path.c_str(), aside.c_str()) == 0;
  spdlog::error("scan {}: sha256 mismatch: the stored file hashes to {}{}", scan_id, actual,
                moved ? "; moved to " + aside : "");
  throw CorruptScanError("scan " + scan_id + ": sha256 mismatch: its file in the data directory " +
                         "hashes to " + actual + (moved ? "; moved to " + aside : "") +
                         " (upload the scan again)");
}

}  // namespace boicp::server
