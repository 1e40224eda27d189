#pragma once
// The daemon's data directory:
//   boicpd.sqlite (+ -wal, -shm)  jobs, scans' metadata, pair results, poses
//   scans/ab/<sha256>             uploaded bytes, named by their hash
//   jobs/<job_id>/                map.bt, map.ot, trajectory.tum, trajectory.kitti, map.ply
//   tmp/                          uploads in progress (emptied at start)
//   lock                          flock()ed while a daemon uses the directory

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace boicp::server {

class DataDir {
 public:
  /// Creates the layout and takes the lock. Throws StorageError when the
  /// directory cannot be created or opened, std::runtime_error when another
  /// daemon holds it.
  explicit DataDir(const std::string& root);
  ~DataDir();
  DataDir(const DataDir&) = delete;
  DataDir& operator=(const DataDir&) = delete;

  const std::string& root() const { return root_; }
  std::string DatabasePath() const;
  /// Throws InputError unless `scan_id` is 64 lowercase hex digits, so that
  /// no client string ever becomes a path outside scans/.
  std::string ScanPath(const std::string& scan_id) const;
  /// False for an id that is not a scan id.
  bool HasScanFile(const std::string& scan_id) const;
  std::string JobDir(const std::string& job_id) const;
  /// The job folders under jobs/, by name.
  std::vector<std::string> JobDirNames() const;

  /// Bytes the stored scans and the jobs' outputs hold: every file under
  /// scans/ and jobs/ at the start, and each change since.
  uint64_t StoredBytes() const;
  /// Counts the job's folder again, after its outputs were written.
  void RecountJobDir(const std::string& job_id);
  /// Removes the job's folder (nothing when it has none); returns the bytes
  /// its files held. A failure is logged, not thrown: the next start removes
  /// a folder no job owns.
  uint64_t RemoveJobDir(const std::string& job_id);
  /// Removes a stored scan's file; returns its bytes.
  uint64_t RemoveScanFile(const std::string& scan_id);
  /// Marks a stored scan used now (its file's time), so that the collection
  /// of unused scans spares it.
  void TouchScan(const std::string& scan_id) const;
  /// The scans whose files were last used before `cutoff`.
  std::vector<std::string> ScansUnusedSince(std::filesystem::file_time_type cutoff) const;
  /// Creates the job's directory (and any missing parent), each synced into
  /// its parent. Returns its path. Throws StorageError.
  std::string CreateJobDir(const std::string& job_id) const;
  /// The directories the daemon creates files in: the root (database), scans/,
  /// jobs/ and tmp/.
  std::vector<std::string> WritableDirs() const;

  /// A fresh path under tmp/ for an upload in progress.
  std::string NewTempPath();

  /// Flushes `tmp_path` to disk and renames it to ScanPath(scan_id). Throws
  /// StorageError when the disk refuses.
  void CommitScan(const std::string& tmp_path, const std::string& scan_id);

 private:
  std::string root_;
  int lock_fd_ = -1;
  std::atomic<uint64_t> temp_counter_{0};
  mutable std::mutex bytes_mutex_;
  uint64_t scan_bytes_ = 0;
  std::map<std::string, uint64_t> job_bytes_;  // by job folder
};

}  // namespace boicp::server
