#include "boicp/util/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace boicp {
namespace {

std::string StagingPath(const std::string& path) {
  return path + "." + std::to_string(::getpid()) + "-" +
         std::to_string(std::hash<std::thread::id>{}(std::this_thread::get_id())) + ".tmp";
}

void SyncFile(const std::string& path, int flags = 0) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | flags);
  if (fd < 0) throw std::runtime_error(path + ": cannot reopen (" + std::strerror(errno) + ")");
  const int rc = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (rc != 0) throw std::runtime_error(path + ": fsync failed (" + std::strerror(error) + ")");
}

std::string ParentDirectory(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

}  // namespace

void WriteFileAtomically(const std::string& path,
                         const std::function<void(const std::string& staging_path)>& write) {
  const std::string staging = StagingPath(path);
  try {
    write(staging);
    SyncFile(staging);
    std::error_code ec;
    std::filesystem::rename(staging, path, ec);
    if (ec) throw std::runtime_error(path + ": cannot replace (" + ec.message() + ")");
    // The rename lives in the directory: until it is synced, a power cut
    // may bring back the old file or none.
    SyncFile(ParentDirectory(path), O_DIRECTORY);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(staging, ignored);
    throw;
  }
}

void WriteTextFileAtomically(const std::string& path, const std::string& content) {
  WriteFileAtomically(path, [&](const std::string& staging) {
    std::ofstream out(staging, std::ios::binary | std::ios::trunc);
    out << content;
    out.close();
    if (!out) throw std::runtime_error(path + ": cannot write");
  });
}

}  // namespace boicp
