#include "atomic_write.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace boicp::detail {
namespace {

void SyncFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(path + ": cannot reopen (" + std::strerror(errno) + ")");
  const int rc = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (rc != 0) throw std::runtime_error(path + ": fsync failed (" + std::strerror(error) + ")");
}

}  // namespace

void WriteFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmp_path)>& write) {
  const std::string tmp = path + ".tmp";
  try {
    write(tmp);
    SyncFile(tmp);
    std::filesystem::rename(tmp, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
}

}  // namespace boicp::detail
