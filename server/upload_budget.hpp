#pragma once
// How many uploads may stream at once and how many bytes they may announce
// together. Each upload holds a ticket from its metadata to its end, so the
// uploads in flight never pass either limit, and the free-space check of a
// new upload counts the bytes the others still have to write. An upload that
// reuses stored bytes holds their size while it re-reads them; the
// free-space check counts those too, which errs on the safe side.

#include <cstdint>
#include <mutex>

namespace boicp::server {

class UploadBudget {
 public:
  UploadBudget(int max_uploads, uint64_t max_bytes)
      : max_uploads_(max_uploads), max_bytes_(max_bytes) {}
  UploadBudget(const UploadBudget&) = delete;
  UploadBudget& operator=(const UploadBudget&) = delete;

  /// One upload's slot and announced bytes, from construction, which throws
  /// ServiceError RESOURCE_EXHAUSTED naming the limit reached, to destruction.
  class Ticket {
   public:
    Ticket(UploadBudget& budget, uint64_t bytes) : budget_(budget), bytes_(bytes) {
      budget.Reserve(bytes);
    }
    ~Ticket() { budget_.Release(bytes_); }
    Ticket(const Ticket&) = delete;
    Ticket& operator=(const Ticket&) = delete;

   private:
    UploadBudget& budget_;
    uint64_t bytes_;
  };

  /// Bytes announced by the uploads in flight.
  uint64_t bytes_in_flight() const;

 private:
  void Reserve(uint64_t bytes);
  void Release(uint64_t bytes);

  const int max_uploads_;
  const uint64_t max_bytes_;
  mutable std::mutex mutex_;
  int uploads_ = 0;
  uint64_t bytes_ = 0;
};

}  // namespace boicp::server
