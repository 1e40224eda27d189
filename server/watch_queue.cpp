#include "watch_queue.hpp"

#include <utility>

namespace boicp::server {

namespace v1 = ::boicp::v1;

void WatchQueue::Push(const v1::JobEvent& event) {
  if (!pending_.empty()) {
    v1::JobEvent& last = pending_.back();
    const bool superseded =
        !last.has_pair() && !event.has_pair() && last.job().stage() == event.job().stage();
    if (superseded || pending_.size() >= capacity_) {
      const uint32_t skipped =
          last.pairs_skipped() + (last.has_pair() ? 1u : 0u) + event.pairs_skipped();
      last = event;
      last.set_pairs_skipped(skipped);
      return;
    }
  }
  pending_.push_back(event);
}

v1::JobEvent WatchQueue::Pop() {
  v1::JobEvent event = std::move(pending_.front());
  pending_.pop_front();
  return event;
}

}  // namespace boicp::server
