#pragma once
// Reads a process's RSS at a fixed interval on its own thread, so a run can
// show whether memory climbs while the daemon is busy or levels off.

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace boicp::load {

class MemorySampler {
 public:
  /// Starts sampling `pid` every `interval` (the first sample after one interval).
  MemorySampler(pid_t pid, std::chrono::milliseconds interval);
  /// Stops (see Stop).
  ~MemorySampler();
  MemorySampler(const MemorySampler&) = delete;
  MemorySampler& operator=(const MemorySampler&) = delete;

  /// Stops sampling and returns the VmRSS samples (MiB) in order. A sample
  /// that could not be read (the process is gone) ends the series.
  std::vector<double> Stop();

 private:
  void Run(pid_t pid, std::chrono::milliseconds interval);

  std::mutex mutex_;
  std::condition_variable stop_requested_;
  bool stopping_ = false;
  std::vector<double> samples_mb_;
  std::thread thread_;
};

}  // namespace boicp::load
