#include "memory_sampler.hpp"

#include "process_memory.hpp"

namespace boicp::load {

MemorySampler::MemorySampler(pid_t pid, std::chrono::milliseconds interval)
    : thread_([this, pid, interval] { Run(pid, interval); }) {}

MemorySampler::~MemorySampler() { Stop(); }

std::vector<double> MemorySampler::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_requested_.notify_all();
  if (thread_.joinable()) thread_.join();
  return samples_mb_;
}

void MemorySampler::Run(pid_t pid, std::chrono::milliseconds interval) {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_requested_.wait_for(lock, interval, [this] { return stopping_; })) {
    try {
      samples_mb_.push_back(ReadProcessMemory(pid).rss_mb);
    } catch (const std::exception&) {
      return;
    }
  }
}

}  // namespace boicp::load
