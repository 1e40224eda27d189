#pragma once
// Ends uploads that stop sending or send too slowly. An open upload holds a
// temp file, a slot and its announced bytes in the upload budget; a client
// that sends its metadata and then nothing, or a byte now and then, while
// keeping the connection alive (keepalive pings and the idle-connection
// timeout do not see a call that is open but silent), would hold them for
// ever. Each upload registers here and reports every message; a thread
// cancels those silent for too long, or behind the minimum rate.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>

#include <grpcpp/server_context.h>

namespace boicp::server {

class UploadWatchdog {
 public:
  using Clock = std::chrono::steady_clock;

  struct Limits {
    Clock::duration idle_timeout{};  // > 0: how long an upload may go without a message
    uint64_t min_bytes_per_s = 0;    // average rate past the grace; 0 = none
    Clock::duration rate_grace{};    // >= 0: the rate is not checked before this
  };

  explicit UploadWatchdog(const Limits& limits);
  /// Joins the thread. Every registered upload must have left first.
  ~UploadWatchdog();
  UploadWatchdog(const UploadWatchdog&) = delete;
  UploadWatchdog& operator=(const UploadWatchdog&) = delete;

  /// Starts timing the upload of `context` (its rate counts from now);
  /// returns its id for the calls below.
  uint64_t Enter(grpc::CallbackServerContext* context);
  /// The upload received a message carrying `bytes` of the scan. Returns why
  /// it is over a limit (naming the flag), or "" while it is within them.
  std::string Touch(uint64_t id, uint64_t bytes);
  /// The client has sent everything: the upload is no longer timed (what
  /// follows, such as waiting for decoding memory, is the daemon's time).
  void Sent(uint64_t id);
  /// Stops timing it; once this returns its context is never used here again.
  void Leave(uint64_t id);
  /// Why the upload was cancelled here, naming the flag; "" when it was not.
  std::string CancelReason(uint64_t id) const;

 private:
  struct Upload {
    grpc::CallbackServerContext* context = nullptr;
    Clock::time_point start;
    Clock::time_point last_message;
    uint64_t bytes = 0;
    bool sent = false;
    std::string cancel_reason;  // set when cancelled here
  };
  std::string OverLimit(const Upload& upload, Clock::time_point now) const;
  void CancelOverdueUploads();

  const Limits limits_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable cancelled_;  // cancelling_ went back to 0
  bool stopping_ = false;
  uint64_t cancelling_ = 0;  // the upload TryCancel is running for, 0 = none
  uint64_t next_id_ = 1;
  std::map<uint64_t, Upload> uploads_;
  std::thread thread_;
};

}  // namespace boicp::server
