#include "upload_watchdog.hpp"

#include <algorithm>
#include <vector>

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

namespace boicp::server {
namespace {

double Seconds(UploadWatchdog::Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

}  // namespace

UploadWatchdog::UploadWatchdog(const Limits& limits)
    : limits_(limits), thread_([this] { CancelOverdueUploads(); }) {}

UploadWatchdog::~UploadWatchdog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

uint64_t UploadWatchdog::Enter(grpc::CallbackServerContext* context) {
  std::lock_guard<std::mutex> lock(mutex_);
  const uint64_t id = next_id_++;
  const Clock::time_point now = Clock::now();
  Upload& upload = uploads_[id];
  upload.context = context;
  upload.start = now;
  upload.last_message = now;
  return id;
}

std::string UploadWatchdog::Touch(uint64_t id, uint64_t bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = uploads_.find(id);
  if (found == uploads_.end()) return "";
  found->second.last_message = Clock::now();
  found->second.bytes += bytes;
  return OverLimit(found->second, found->second.last_message);
}

void UploadWatchdog::Sent(uint64_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto found = uploads_.find(id); found != uploads_.end()) found->second.sent = true;
}

void UploadWatchdog::Leave(uint64_t id) {
  std::unique_lock<std::mutex> lock(mutex_);
  // Should gRPC run the upload's end inside TryCancel, it runs on the thread
  // below, which must not wait for itself.
  if (std::this_thread::get_id() != thread_.get_id()) {
    cancelled_.wait(lock, [&] { return cancelling_ != id; });
  }
  uploads_.erase(id);
}

std::string UploadWatchdog::CancelReason(uint64_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = uploads_.find(id);
  return found == uploads_.end() ? "" : found->second.cancel_reason;
}

// The rate is an average from the upload's start, less the grace: past it,
// each second must have brought its share, so one byte now and then (which
// resets no idle timer worth having) cannot keep a slot.
std::string UploadWatchdog::OverLimit(const Upload& upload, Clock::time_point now) const {
  if (upload.sent) return "";
  if (now - upload.last_message >= limits_.idle_timeout) {
    return fmt::format("the upload sent nothing for {:.0f} s (--upload-idle-timeout)",
                       Seconds(now - upload.last_message));
  }
  const Clock::duration timed = now - upload.start - limits_.rate_grace;
  if (limits_.min_bytes_per_s == 0 || timed <= Clock::duration::zero()) return "";
  const double owed = static_cast<double>(limits_.min_bytes_per_s) * Seconds(timed);
  if (static_cast<double>(upload.bytes) >= owed) return "";
  return fmt::format(
      "the upload sent {} bytes in {:.1f} s, under the minimum of {} KiB/s after the first "
      "{:.0f} s (--min-upload-kib-per-s, --upload-rate-grace)",
      upload.bytes, Seconds(now - upload.start), limits_.min_bytes_per_s / 1024,
      Seconds(limits_.rate_grace));
}

// TryCancel runs without the mutex (the reactions it causes may take it),
// and Leave waits for it, so the context stays alive throughout.
void UploadWatchdog::CancelOverdueUploads() {
  Clock::duration poll = limits_.idle_timeout / 4;
  if (limits_.min_bytes_per_s > 0) poll = std::min(poll, limits_.rate_grace / 4);
  poll = std::max<Clock::duration>(poll, std::chrono::milliseconds(50));
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, poll);
    const Clock::time_point now = Clock::now();
    std::vector<std::pair<uint64_t, std::string>> overdue;
    for (const auto& [id, upload] : uploads_) {
      if (!upload.cancel_reason.empty()) continue;
      if (std::string reason = OverLimit(upload, now); !reason.empty()) {
        overdue.emplace_back(id, std::move(reason));
      }
    }
    for (auto& [id, reason] : overdue) {
      const auto found = uploads_.find(id);
      if (found == uploads_.end() || found->second.sent) continue;
      spdlog::warn("{}: cancelled", reason);
      found->second.cancel_reason = std::move(reason);
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
