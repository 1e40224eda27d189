#include "watch_hub.hpp"

#include <vector>

#include "boicp/rpc/proto_convert.hpp"
#include "watch_queue.hpp"

namespace boicp::server {
namespace {

// Events one watcher may have queued (WatchQueue says what gives way past it).
constexpr size_t kMaxPendingEvents = 64;

}  // namespace

// Every field below is guarded by the hub's mutex.
class WatchHub::Stream : public grpc::ServerWriteReactor<v1::JobEvent> {
 public:
  Stream(WatchHub& hub, std::string job_id) : hub_(hub), job_id(std::move(job_id)) {}

  void OnWriteDone(bool ok) override {
    std::lock_guard<std::mutex> lock(hub_.mutex_);
    writing = false;
    if (!ok && !finish_requested) RequestFinish(grpc::Status::CANCELLED);
    Wake();
  }

  void OnCancel() override {
    std::lock_guard<std::mutex> lock(hub_.mutex_);
    if (!finish_requested) RequestFinish(grpc::Status::CANCELLED);
    Wake();
  }

  void OnDone() override {
    if (!registered) {
      delete this;
      return;
    }
    std::lock_guard<std::mutex> lock(hub_.mutex_);
    done = true;
    --hub_.open_streams_;
    Wake();
  }

  void RequestFinish(const grpc::Status& s) {
    finish_requested = true;
    status = s;
  }

  void Wake() {
    hub_.work_ = true;
    hub_.wake_.notify_one();
  }

  WatchHub& hub_;
  const std::string job_id;
  WatchQueue pending{kMaxPendingEvents};
  v1::JobEvent current;  // the event being written; untouched while writing
  bool registered = false;
  bool writing = false;
  bool finish_requested = false;
  bool finish_called = false;
  bool done = false;
  grpc::Status status;
};

WatchHub::WatchHub(int max_streams) : max_streams_(max_streams), pump_([this] { Pump(); }) {}

WatchHub::~WatchHub() {
  CloseAll(grpc::Status(grpc::StatusCode::UNAVAILABLE, "boicpd is shutting down"));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    work_ = true;
  }
  wake_.notify_one();
  pump_.join();
}

void WatchHub::Publish(const v1::JobEvent& event) {
  std::lock_guard<std::mutex> lock(mutex_);
  // A final state is published only once stored, so the store answers for
  // finished jobs and the cache holds only the ones still running.
  if (rpc::IsTerminal(event.job().state())) {
    latest_.erase(event.job().job_id());
  } else {
    latest_[event.job().job_id()] = event.job();
  }
  for (Stream* stream : streams_) {
    if (stream->job_id == event.job().job_id() && !stream->finish_requested) {
      stream->pending.Push(event);
    }
  }
  work_ = true;
  wake_.notify_one();
}

std::optional<v1::Job> WatchHub::Latest(const std::string& job_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = latest_.find(job_id);
  if (found == latest_.end()) return std::nullopt;
  return found->second;
}

grpc::ServerWriteReactor<v1::JobEvent>* WatchHub::StartWatch(const std::string& job_id,
                                                             const std::optional<v1::Job>& stored) {
  auto* stream = new Stream(*this, job_id);
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<v1::Job> snapshot = stored;
  if (const auto found = latest_.find(job_id); found != latest_.end()) snapshot = found->second;
  if (!snapshot) {
    stream->Finish(grpc::Status(grpc::StatusCode::NOT_FOUND, "no job '" + job_id + "'"));
    return stream;
  }
  if (stopping_) {
    stream->Finish(grpc::Status(grpc::StatusCode::UNAVAILABLE, "boicpd is shutting down"));
    return stream;
  }
  if (open_streams_ >= max_streams_) {
    stream->Finish(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                                std::to_string(open_streams_) +
                                    " WatchJob streams are open, this daemon's limit "
                                    "(--max-watch-streams " +
                                    std::to_string(max_streams_) +
                                    "); poll GetJob, or watch once a stream ends"));
    return stream;
  }
  stream->registered = true;
  ++open_streams_;
  v1::JobEvent first;
  *first.mutable_job() = *snapshot;
  stream->pending.Push(first);
  streams_.push_back(stream);
  work_ = true;
  wake_.notify_one();
  return stream;
}

void WatchHub::CloseAll(const grpc::Status& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (Stream* stream : streams_) {
    if (!stream->finish_requested) {
      stream->pending.Clear();
      stream->RequestFinish(status);
    }
  }
  work_ = true;
  wake_.notify_one();
}

void WatchHub::Pump() {
  struct Action {
    Stream* stream;
    bool finish;
    grpc::Status status;
  };
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return work_; });
    work_ = false;
    std::vector<Action> actions;
    for (auto it = streams_.begin(); it != streams_.end();) {
      Stream* s = *it;
      if (s->done) {  // OnDone ran: gRPC no longer uses it
        delete s;
        it = streams_.erase(it);
        continue;
      }
      ++it;
      if (s->writing || s->finish_called) continue;
      if (s->finish_requested) {
        s->finish_called = true;
        actions.push_back({s, true, s->status});
      } else if (!s->pending.empty()) {
        s->current = s->pending.Pop();
        s->writing = true;
        if (rpc::IsTerminal(s->current.job().state())) s->RequestFinish(grpc::Status::OK);
        actions.push_back({s, false, {}});
      }
    }
    if (stopping_ && streams_.empty()) return;
    // Reactions may run inline inside StartWrite / Finish and take the mutex.
    lock.unlock();
    for (Action& action : actions) {
      if (action.finish) {
        action.stream->Finish(action.status);
      } else {
        action.stream->StartWrite(&action.stream->current);
      }
    }
    lock.lock();
  }
}

}  // namespace boicp::server
