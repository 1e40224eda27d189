#include "idle_uploads.hpp"

#include <algorithm>
#include <vector>

#include <spdlog/spdlog.h>

namespace boicp::server {

IdleUploads::IdleUploads(Clock::duration timeout)
    : timeout_(timeout), thread_([this] { CancelSilentUploads(); }) {}

IdleUploads::~IdleUploads() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

uint64_t IdleUploads::Enter(grpc::CallbackServerContext* context) {
  std::lock_guard<std::mutex> lock(mutex_);
  const uint64_t id = next_id_++;
  uploads_[id] = {context, Clock::now()};
  return id;
}

void IdleUploads::Touch(uint64_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto found = uploads_.find(id); found != uploads_.end()) {
    found->second.last_message = Clock::now();
  }
}

void IdleUploads::Leave(uint64_t id) {
  std::unique_lock<std::mutex> lock(mutex_);
  // Should gRPC run the upload's end inside TryCancel, it runs on the thread
  // below, which must not wait for itself.
  if (std::this_thread::get_id() != thread_.get_id()) {
    cancelled_.wait(lock, [&] { return cancelling_ != id; });
  }
  uploads_.erase(id);
}

bool IdleUploads::TimedOut(uint64_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = uploads_.find(id);
  return found != uploads_.end() && found->second.timed_out;
}

// TryCancel runs without the mutex (the reactions it causes may take it),
// and Leave waits for it, so the context stays alive throughout.
void IdleUploads::CancelSilentUploads() {
  const Clock::duration poll =
      std::max<Clock::duration>(timeout_ / 4, std::chrono::milliseconds(50));
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, poll);
    const Clock::time_point now = Clock::now();
    std::vector<uint64_t> silent;
    for (const auto& [id, upload] : uploads_) {
      if (!upload.timed_out && now - upload.last_message >= timeout_) silent.push_back(id);
    }
    for (const uint64_t id : silent) {
      const auto found = uploads_.find(id);
      if (found == uploads_.end()) continue;
      found->second.timed_out = true;
      spdlog::warn("an upload sent nothing for {:.0f} s: cancelled (--upload-idle-timeout)",
                   std::chrono::duration<double>(now - found->second.last_message).count());
      grpc::CallbackServerContext* context = found->second.context;
      cancelling_ = id;
      lock.unlock();
      context->TryCancel();
      lock.lock();
      cancelling_ = 0;
      cancelled_.notify_all();
    }
  }
}

}  // namespace boicp::server
