#pragma once
// WatchJob streams. Events come from job threads, but a callback-API reactor
// must not be written to from arbitrary threads while its own reactions may
// run inline and delete it. So one pump thread owns every StartWrite and
// Finish call and every deletion; reactions and publishers only change
// state under the hub's mutex and wake the pump.

#include <condition_variable>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <grpcpp/support/server_callback.h>

#include "job_events.hpp"

namespace boicp::server {

namespace v1 = ::boicp::v1;

class WatchHub : public JobEventSink {
 public:
  /// `max_streams` >= 1: streams open at once, all jobs and clients together.
  explicit WatchHub(int max_streams);
  /// Ends every stream with UNAVAILABLE, waits until gRPC has released
  /// them, and joins the pump. Shut the gRPC server down first.
  ~WatchHub() override;
  WatchHub(const WatchHub&) = delete;
  WatchHub& operator=(const WatchHub&) = delete;

  void Publish(const v1::JobEvent& event) override;

  /// The newest snapshot published for the job while it runs (a finished
  /// job's final state is in the store), if any since the start.
  std::optional<v1::Job> Latest(const std::string& job_id) const;

  /// A reactor for one WatchJob call. Its first event is the newest
  /// snapshot (or `stored` when nothing was published for the job); without
  /// either it finishes with NOT_FOUND. It ends with OK after the first event
  /// with a final state. With max_streams already open it finishes with
  /// RESOURCE_EXHAUSTED: each stream holds a queue and a gRPC call for as
  /// long as its job runs, so watchers alone could otherwise exhaust memory.
  grpc::ServerWriteReactor<v1::JobEvent>* StartWatch(const std::string& job_id,
                                                     const std::optional<v1::Job>& stored);

  /// Ends every open stream with `status` (the daemon is draining).
  void CloseAll(const grpc::Status& status);

 private:
  class Stream;
  void Pump();

  const int max_streams_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool work_ = false;
  bool stopping_ = false;
  std::map<std::string, v1::Job> latest_;
  std::list<Stream*> streams_;
  int open_streams_ = 0;  // in streams_ and not yet done
  std::thread pump_;
};

}  // namespace boicp::server
