#pragma once
// A process-wide budget of decoding memory: a byte-counting admission gate
// that the scans decoded at once (uploads checked, pair pyramids built,
// scans fused) share, so that their sum stays under one limit however many
// uploads and workers run. A decode whose bound does not fit waits for the
// bytes others hold; one that could never fit is refused at once.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>

namespace boicp {

class DecodeBudget {
 public:
  /// A share of the budget, returned on destruction. Move-only; a
  /// default-constructed lease holds nothing.
  class Lease {
   public:
    Lease() = default;
    ~Lease() { Release(); }
    Lease(Lease&& other) noexcept;
    Lease& operator=(Lease&& other) noexcept;
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;

    /// Bytes held (0 for an empty lease).
    uint64_t bytes() const { return bytes_; }

   private:
    friend class DecodeBudget;
    Lease(DecodeBudget* budget, uint64_t bytes) : budget_(budget), bytes_(bytes) {}
    void Release();

    DecodeBudget* budget_ = nullptr;
    uint64_t bytes_ = 0;
  };

  /// A budget of `limit_bytes` (> 0; throws std::invalid_argument for 0).
  /// It must outlive every lease taken from it.
  explicit DecodeBudget(uint64_t limit_bytes);
  DecodeBudget(const DecodeBudget&) = delete;
  DecodeBudget& operator=(const DecodeBudget&) = delete;

  /// Takes `bytes`, waiting until they fit under the limit beside the leases
  /// held. Waiters are admitted in arrival order, so a large decode is not
  /// passed over for ever by small ones. Throws LimitExceeded, naming
  /// --max-decode-mb, at once when `bytes` is over the whole limit, and
  /// Cancelled when `stop_requested` (polled every few tens of milliseconds
  /// while waiting; may be empty) returns true or the budget is closed.
  /// Thread-safe. 0 bytes returns an empty lease at once.
  Lease Acquire(uint64_t bytes, const std::function<bool()>& stop_requested = {});

  /// Ends every wait, and every later Acquire of bytes, with Cancelled;
  /// leases held stay valid. For shutdown: no decode starts or waits past it.
  void Close();

  uint64_t limit_bytes() const { return limit_; }
  /// Bytes the leases hold now.
  uint64_t held_bytes() const;
  /// Acquire calls waiting now (tests use it to know a caller is blocked).
  size_t waiting() const;

 private:
  void Release(uint64_t bytes);

  const uint64_t limit_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  uint64_t held_ = 0;
  bool closed_ = false;
  uint64_t next_ticket_ = 0;
  std::deque<uint64_t> queue_;  // tickets of the waiters, first come first
};

}  // namespace boicp
