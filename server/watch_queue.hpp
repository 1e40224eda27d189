#pragma once
// The events one WatchJob stream has yet to send, bounded so that a watcher
// reading slower than its job reports cannot make the daemon hold an ever
// longer backlog. What it merges away it says: the next event sent carries
// the number of finished-pair events the watcher missed (a gap marker).

#include <cstddef>
#include <deque>

#include "boicp/v1/map_builder.pb.h"

namespace boicp::server {

class WatchQueue {
 public:
  /// `capacity` >= 1: events held at most.
  explicit WatchQueue(size_t capacity) : capacity_(capacity) {}

  /// Queues `event`. A progress snapshot with no pair replaces a queued one of
  /// the same stage (it supersedes it and loses nothing). At capacity, the
  /// newest event replaces the last queued one; a pair result that gives way
  /// is counted in the replacement's pairs_skipped. A final state is never
  /// replaced: it is the last event a job publishes.
  void Push(const ::boicp::v1::JobEvent& event);

  bool empty() const { return pending_.empty(); }
  size_t size() const { return pending_.size(); }

  /// The oldest queued event. Precondition: !empty().
  ::boicp::v1::JobEvent Pop();

  void Clear() { pending_.clear(); }

 private:
  size_t capacity_;
  std::deque<::boicp::v1::JobEvent> pending_;
};

}  // namespace boicp::server
