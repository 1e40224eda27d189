#pragma once
// A fixed set of worker threads running tasks in FIFO order: where the map
// pipeline's pair registrations run. The daemon has one for all its jobs
// (its size is --workers, so nothing else creates registration threads);
// `boicp map` has one of --threads workers. Plain threads, not oneTBB tasks:
// oneTBB gives a process one worker fewer than its cores unless a
// process-wide global_control says otherwise, so --workers pairs would not
// all run at once.

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace boicp {

class ThreadPool {
 public:
  /// Starts `threads` workers (at least 1).
  explicit ThreadPool(int threads);
  /// Runs the tasks already queued, then joins the workers.
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  void Submit(std::function<void()> task);
  int size() const { return static_cast<int>(workers_.size()); }

 private:
  void Work();

  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::function<void()>> tasks_;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace boicp
