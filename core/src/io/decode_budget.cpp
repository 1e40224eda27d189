#include "boicp/io/decode_budget.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "boicp/util/types.hpp"

namespace boicp {

namespace {

// How often a waiter polls its stop request: well within the time a job
// takes to stop between pairs, and cheap against a decode's seconds.
constexpr std::chrono::milliseconds kStopPoll{20};

std::string Mebibytes(uint64_t bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20); }

}  // namespace

DecodeBudget::Lease::Lease(Lease&& other) noexcept : budget_(other.budget_), bytes_(other.bytes_) {
  other.budget_ = nullptr;
  other.bytes_ = 0;
}

DecodeBudget::Lease& DecodeBudget::Lease::operator=(Lease&& other) noexcept {
  if (this != &other) {
    Release();
    budget_ = other.budget_;
    bytes_ = other.bytes_;
    other.budget_ = nullptr;
    other.bytes_ = 0;
  }
  return *this;
}

void DecodeBudget::Lease::Release() {
  if (budget_ != nullptr) budget_->Release(bytes_);
  budget_ = nullptr;
  bytes_ = 0;
}

DecodeBudget::DecodeBudget(uint64_t limit_bytes) : limit_(limit_bytes) {
  if (limit_bytes == 0) throw std::invalid_argument("a decode budget needs a limit above 0");
}

DecodeBudget::Lease DecodeBudget::Acquire(uint64_t bytes,
                                          const std::function<bool()>& stop_requested) {
  if (bytes == 0) return Lease();
  if (bytes > limit_) {
    throw LimitExceeded("decoding needs up to " + Mebibytes(bytes) +
                        " MiB, over the decode budget of " + Mebibytes(limit_) +
                        " MiB (--max-decode-mb)");
  }
  std::unique_lock<std::mutex> lock(mutex_);
  const uint64_t ticket = next_ticket_++;
  queue_.push_back(ticket);
  const auto leave = [&] {
    queue_.erase(std::find(queue_.begin(), queue_.end(), ticket));
    // The next in line may fit now that this one no longer blocks it.
    changed_.notify_all();
  };
  while (closed_ || queue_.front() != ticket || held_ + bytes > limit_) {
    if (closed_ || (stop_requested && stop_requested())) {
      leave();
      throw Cancelled();
    }
    changed_.wait_for(lock, kStopPoll);
  }
  queue_.pop_front();
  held_ += bytes;
  changed_.notify_all();  // the next in line may fit beside this one
  return Lease(this, bytes);
}

void DecodeBudget::Close() {
  std::lock_guard<std::mutex> lock(mutex_);
  closed_ = true;
  changed_.notify_all();
}

uint64_t DecodeBudget::held_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return held_;
}

size_t DecodeBudget::waiting() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return queue_.size();
}

void DecodeBudget::Release(uint64_t bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  held_ -= bytes;
  changed_.notify_all();
}

}  // namespace boicp
