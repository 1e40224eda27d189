#include "storage_check.hpp"

#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

#include "service_error.hpp"
#include "storage_errors.hpp"

namespace boicp::server {
namespace {

std::string Mebibytes(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f MiB", static_cast<double>(bytes) / (1 << 20));
  return text;
}

// Creates and removes a file in `dir`. An unnamed O_TMPFILE file leaves
// nothing behind if the daemon dies here; file systems without it get a
// named probe.
std::optional<std::string> CannotCreateFileIn(const std::string& dir) {
  int fd = ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0600);
  if (fd < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
    std::string probe = dir + "/.write-probe-XXXXXX";
    fd = ::mkostemp(probe.data(), O_CLOEXEC);
    if (fd >= 0) ::unlink(probe.c_str());
  }
  if (fd < 0) return std::string(std::strerror(errno));
  ::close(fd);
  return std::nullopt;
}

}  // namespace

std::optional<StorageError> FindStorageProblem(const DataDir& dir, uint64_t reserve_bytes,
                                               uint64_t incoming_bytes) {
  const std::string name = "data directory " + dir.root();
  for (const std::string& sub : dir.WritableDirs()) {
    if (const auto reason = CannotCreateFileIn(sub)) {
      return StorageError(name + " is not writable: cannot create a file in " + sub + " (" +
                          *reason + ")");
    }
  }
  struct statvfs fs {};
  if (::statvfs(dir.root().c_str(), &fs) != 0) {
    return StorageError(name + ": cannot read its free space (" + std::strerror(errno) + ")");
  }
  if (fs.f_files > 0 && fs.f_favail == 0) return StorageError(name + " is full: no free inodes");
  const uint64_t free_bytes = static_cast<uint64_t>(fs.f_bavail) * fs.f_frsize;
  const uint64_t needed = reserve_bytes > std::numeric_limits<uint64_t>::max() - incoming_bytes
                              ? std::numeric_limits<uint64_t>::max()
                              : reserve_bytes + incoming_bytes;
  if (free_bytes >= needed) return std::nullopt;
  const std::string upload =
      incoming_bytes > 0 ? "; this upload needs " + Mebibytes(incoming_bytes) + " more" : "";
  const std::string reserve = "boicpd keeps " + Mebibytes(reserve_bytes) + " free (--min-free-mb " +
                              std::to_string(reserve_bytes >> 20) + ")";
  // How much is free goes to the daemon's log, not to clients.
  return StorageError(
      name + " is nearly full: " + Mebibytes(free_bytes) + " free" + upload + ", and " + reserve,
      name + " is nearly full" + upload + ": " + reserve);
}

void RequireStoredQuota(const DataDir& dir, uint64_t max_stored_bytes, uint64_t incoming_bytes) {
  if (max_stored_bytes == 0) return;
  const uint64_t stored = dir.StoredBytes();
  if (stored + incoming_bytes <= max_stored_bytes) return;
  char gigabytes[32];
  std::snprintf(gigabytes, sizeof gigabytes, "%g", static_cast<double>(max_stored_bytes) / 1e9);
  throw ServiceError(
      grpc::StatusCode::RESOURCE_EXHAUSTED,
      "stored scans and outputs take " + Mebibytes(stored) +
          (incoming_bytes > 0 ? ", " + Mebibytes(incoming_bytes) + " more coming" : std::string()) +
          ", over --max-stored-gb " + gigabytes +
          "; delete finished jobs (boicp delete) to free room: the scans no job "
          "uses go after --scan-grace-hours");
}

void RequireStorage(const DataDir& dir, uint64_t reserve_bytes, uint64_t incoming_bytes) {
  if (auto problem = FindStorageProblem(dir, reserve_bytes, incoming_bytes)) throw *problem;
}

}  // namespace boicp::server
