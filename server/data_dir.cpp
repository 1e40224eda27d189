#include "data_dir.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "boicp/rpc/sha256.hpp"
#include "boicp/util/types.hpp"
#include "storage_errors.hpp"

namespace boicp::server {
namespace fs = std::filesystem;
namespace {

void FsyncPath(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) throw StorageError(path + ": cannot open (" + std::strerror(errno) + ")");
  const int rc = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (rc != 0) throw StorageError(path + ": fsync failed (" + std::strerror(error) + ")");
}

constexpr const char* kSubdirs[] = {"scans", "jobs", "tmp"};

std::error_code SyncDirectory(const fs::path& dir) {
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return {errno, std::generic_category()};
  const int rc = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  return rc == 0 ? std::error_code() : std::error_code(error, std::generic_category());
}

// create_directories, with each new directory's entry synced into its
// parent, so that a power cut cannot take back a directory whose files were
// already reported stored. Returns the first error.
std::error_code CreateDurableDirectories(const fs::path& dir) {
  std::error_code error;
  if (dir.empty() || fs::exists(dir, error)) return error;
  error = CreateDurableDirectories(dir.parent_path());
  if (!error) fs::create_directory(dir, error);
  if (!error) error = SyncDirectory(dir.parent_path());
  return error;
}

// Bytes of the files under `path` (0 when it is missing).
uint64_t TreeBytes(const fs::path& path) {
  uint64_t bytes = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(path, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    std::error_code size_error;
    if (it->is_regular_file(size_error)) bytes += it->file_size(size_error);
  }
  return bytes;
}

void RequireDurableDirectories(const fs::path& dir) {
  if (const std::error_code error = CreateDurableDirectories(dir)) {
    throw StorageError("cannot create " + dir.string() + " (" + error.message() + ")");
  }
}

}  // namespace

DataDir::DataDir(const std::string& root) : root_(fs::absolute(root).lexically_normal().string()) {
  for (const char* sub : kSubdirs) {
    if (const std::error_code error = CreateDurableDirectories(fs::path(root_) / sub)) {
      throw StorageError("data directory " + root_ + ": cannot create " + sub + "/ (" +
                         error.message() + ")");
    }
  }
  const std::string lock_path = (fs::path(root_) / "lock").string();
  // Owner only, also when an older daemon left it readable by all.
  lock_fd_ = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (lock_fd_ >= 0) ::fchmod(lock_fd_, 0600);
  if (lock_fd_ < 0) {
    throw StorageError("data directory " + root_ + ": cannot open its lock file (" +
                       std::strerror(errno) + ")");
  }
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    throw std::runtime_error(root_ + ": another boicpd is using this data directory");
  }
  // Leftovers of uploads that were in flight when a daemon died.
  std::error_code error;
  for (fs::directory_iterator it(fs::path(root_) / "tmp", error), end; !error && it != end;
       it.increment(error)) {
    std::error_code ignored;
    fs::remove_all(it->path(), ignored);
  }
  if (error) {
    ::close(lock_fd_);
    throw StorageError("data directory " + root_ + ": cannot read tmp/ (" + error.message() + ")");
  }
  scan_bytes_ = TreeBytes(fs::path(root_) / "scans");
  for (const std::string& name : JobDirNames()) job_bytes_[name] = TreeBytes(JobDir(name));
}

DataDir::~DataDir() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // closing releases the flock
}

std::string DataDir::DatabasePath() const { return (fs::path(root_) / "boicpd.sqlite").string(); }

std::string DataDir::ScanPath(const std::string& scan_id) const {
  if (!rpc::IsSha256Hex(scan_id)) throw InputError("'" + scan_id + "' is not a scan id");
  return (fs::path(root_) / "scans" / scan_id.substr(0, 2) / scan_id).string();
}

bool DataDir::HasScanFile(const std::string& scan_id) const {
  if (!rpc::IsSha256Hex(scan_id)) return false;
  std::error_code ec;
  return fs::is_regular_file(ScanPath(scan_id), ec);
}

std::string DataDir::JobDir(const std::string& job_id) const {
  return (fs::path(root_) / "jobs" / job_id).string();
}

std::vector<std::string> DataDir::JobDirNames() const {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(fs::path(root_) / "jobs", ec), end; !ec && it != end;
       it.increment(ec)) {
    names.push_back(it->path().filename().string());
  }
  return names;
}

uint64_t DataDir::StoredBytes() const {
  std::lock_guard<std::mutex> lock(bytes_mutex_);
  uint64_t bytes = scan_bytes_;
  for (const auto& entry : job_bytes_) bytes += entry.second;
  return bytes;
}

void DataDir::RecountJobDir(const std::string& job_id) {
  const uint64_t bytes = TreeBytes(JobDir(job_id));
  std::lock_guard<std::mutex> lock(bytes_mutex_);
  job_bytes_[job_id] = bytes;
}

uint64_t DataDir::RemoveJobDir(const std::string& job_id) {
  const fs::path dir = JobDir(job_id);
  const uint64_t bytes = TreeBytes(dir);
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (ec) spdlog::warn("cannot remove {}: {}", dir.string(), ec.message());
  std::lock_guard<std::mutex> lock(bytes_mutex_);
  job_bytes_.erase(job_id);
  return bytes;
}

uint64_t DataDir::RemoveScanFile(const std::string& scan_id) {
  const std::string path = ScanPath(scan_id);
  std::error_code ec;
  const uint64_t bytes = fs::file_size(path, ec);
  if (ec || !fs::remove(path, ec)) return 0;
  std::lock_guard<std::mutex> lock(bytes_mutex_);
  scan_bytes_ -= std::min(scan_bytes_, bytes);
  return bytes;
}

void DataDir::TouchScan(const std::string& scan_id) const {
  std::error_code ignored;
  fs::last_write_time(ScanPath(scan_id), fs::file_time_type::clock::now(), ignored);
}

std::vector<std::string> DataDir::ScansUnusedSince(fs::file_time_type cutoff) const {
  std::vector<std::string> ids;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(fs::path(root_) / "scans", ec), end; !ec && it != end;
       it.increment(ec)) {
    std::error_code time_error;
    const std::string name = it->path().filename().string();
    if (it->is_regular_file(time_error) && rpc::IsSha256Hex(name) &&
        it->last_write_time(time_error) < cutoff && !time_error) {
      ids.push_back(name);
    }
  }
  return ids;
}

std::vector<std::string> DataDir::WritableDirs() const {
  std::vector<std::string> dirs = {root_};
  for (const char* sub : kSubdirs) dirs.push_back((fs::path(root_) / sub).string());
  return dirs;
}

std::string DataDir::NewTempPath() {
  return (fs::path(root_) / "tmp" /
          ("upload-" + std::to_string(::getpid()) + "-" + std::to_string(temp_counter_++)))
      .string();
}

std::string DataDir::CreateJobDir(const std::string& job_id) const {
  const std::string dir = JobDir(job_id);
  RequireDurableDirectories(dir);
  return dir;
}

void DataDir::CommitScan(const std::string& tmp_path, const std::string& scan_id) {
  const fs::path target = ScanPath(scan_id);
  RequireDurableDirectories(target.parent_path());
  std::error_code error;
  FsyncPath(tmp_path, O_RDONLY);
  std::error_code size_error;
  const uint64_t bytes = fs::file_size(tmp_path, size_error);
  fs::rename(tmp_path, target, error);
  if (error) {
    throw StorageError("cannot store scan " + scan_id.substr(0, 12) + " in " + root_ + " (" +
                       error.message() + ")");
  }
  FsyncPath(target.parent_path().string(), O_RDONLY | O_DIRECTORY);
  std::lock_guard<std::mutex> lock(bytes_mutex_);
  if (!size_error) scan_bytes_ += bytes;
}

}  // namespace boicp::server
