#pragma once
// The daemon's data directory:
//   boicpd.sqlite (+ -wal, -shm)  jobs, scans' metadata, pair results, poses
//   scans/ab/<sha256>             uploaded bytes, named by their hash
//   jobs/<job_id>/                map.bt, map.ot, trajectory.tum, trajectory.kitti, map.ply
//   tmp/                          uploads in progress (emptied at start)
//   lock                          flock()ed while a daemon uses the directory

#include <atomic>
#include <cstdint>
#include <string>

namespace boicp::server {

class DataDir {
 public:
  /// Creates the layout and takes the lock. Throws std::runtime_error when
  /// the directory cannot be created or another daemon holds it.
  explicit DataDir(const std::string& root);
  ~DataDir();
  DataDir(const DataDir&) = delete;
  DataDir& operator=(const DataDir&) = delete;

  const std::string& root() const { return root_; }
  std::string DatabasePath() const;
  std::string ScanPath(const std::string& scan_id) const;
  bool HasScanFile(const std::string& scan_id) const;
  std::string JobDir(const std::string& job_id) const;

  /// A fresh path under tmp/ for an upload in progress.
  std::string NewTempPath();

  /// Flushes `tmp_path` to disk and renames it to ScanPath(scan_id).
  void CommitScan(const std::string& tmp_path, const std::string& scan_id) const;

 private:
  std::string root_;
  int lock_fd_ = -1;
  std::atomic<uint64_t> temp_counter_{0};
};

}  // namespace boicp::server
