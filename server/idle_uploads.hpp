#pragma once
// Ends uploads that stop sending. An open upload holds a temp file, a slot
// and its announced bytes in the upload budget; a client that sends its
// metadata and then nothing, while keeping the connection alive (keepalive
// pings and the idle-connection timeout do not see a call that is open but
// silent), would hold them for ever. Each upload registers here and is
// touched on every message; a thread cancels those silent for too long.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <thread>

#include <grpcpp/server_context.h>

namespace boicp::server {

class IdleUploads {
 public:
  using Clock = std::chrono::steady_clock;

  /// `timeout` > 0: how long an upload may go without a message.
  explicit IdleUploads(Clock::duration timeout);
  /// Joins the thread. Every registered upload must have left first.
  ~IdleUploads();
  IdleUploads(const IdleUploads&) = delete;
  IdleUploads& operator=(const IdleUploads&) = delete;

  /// Starts timing the upload of `context`; returns its id for Touch and Leave.
  uint64_t Enter(grpc::CallbackServerContext* context);
  /// The upload received a message.
  void Touch(uint64_t id);
  /// Stops timing it; once this returns its context is never used here again.
  void Leave(uint64_t id);
  /// Whether the upload was cancelled for being silent too long.
  bool TimedOut(uint64_t id) const;

  Clock::duration timeout() const { return timeout_; }

 private:
  struct Upload {
    grpc::CallbackServerContext* context;
    Clock::time_point last_message;
    bool timed_out = false;
  };
  void CancelSilentUploads();

  const Clock::duration timeout_;
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
