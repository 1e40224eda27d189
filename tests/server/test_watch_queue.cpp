// A slow watcher's queue stays bounded, says what it merged away (the gap
// marker pairs_skipped), and still delivers the first and the final state.

#include <gtest/gtest.h>

#include "watch_queue.hpp"

namespace boicp::server {
namespace {

namespace v1 = ::boicp::v1;

constexpr size_t kCapacity = 64;
constexpr uint32_t kPairs = 500;

v1::JobEvent Snapshot(const std::string& stage, uint32_t pairs_done,
                      v1::JobState state = v1::JOB_STATE_RUNNING) {
  v1::JobEvent event;
  event.mutable_job()->set_job_id("j");
  event.mutable_job()->set_state(state);
  event.mutable_job()->set_stage(stage);
  event.mutable_job()->set_pairs_done(pairs_done);
  return event;
}

v1::JobEvent PairEvent(uint32_t pairs_done) {
  v1::JobEvent event = Snapshot("registering", pairs_done);
  event.mutable_pair()->set_source(pairs_done);
  event.mutable_pair()->set_target(pairs_done - 1);
  return event;
}

struct Delivered {
  std::vector<v1::JobEvent> events;
  uint32_t pairs = 0;    // pair results received
  uint32_t skipped = 0;  // pair results the gap markers said were missed
};

Delivered Drain(WatchQueue& queue) {
  Delivered delivered;
  while (!queue.empty()) {
    delivered.events.push_back(queue.Pop());
    delivered.pairs += delivered.events.back().has_pair() ? 1 : 0;
    delivered.skipped += delivered.events.back().pairs_skipped();
  }
  return delivered;
}

TEST(WatchQueue, AWatcherThatNeverReadsGetsAGapMarkerForEveryPairItMissed) {
  WatchQueue queue(kCapacity);
  queue.Push(Snapshot("queued", 0));
  queue.Push(Snapshot("registering", 0));
  for (uint32_t p = 1; p <= kPairs; ++p) {
    queue.Push(PairEvent(p));
    queue.Push(Snapshot("registering", p));  // the one-second progress event
    ASSERT_LE(queue.size(), kCapacity);
  }
  queue.Push(Snapshot("fusing", kPairs));
  queue.Push(Snapshot("done", kPairs, v1::JOB_STATE_SUCCEEDED));
  const Delivered delivered = Drain(queue);
  EXPECT_LT(delivered.pairs, kPairs);
  EXPECT_EQ(delivered.pairs + delivered.skipped, kPairs);
  EXPECT_EQ(delivered.events.front().job().stage(), "queued");
  EXPECT_EQ(delivered.events.back().job().state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_GT(delivered.events.back().pairs_skipped(), 0u) << "the gap is told with the final state";
}

TEST(WatchQueue, AWatcherThatKeepsUpSeesEveryPairAndNoGap) {
  WatchQueue queue(kCapacity);
  Delivered all;
  for (uint32_t p = 1; p <= kPairs; ++p) {
    queue.Push(PairEvent(p));
    queue.Push(Snapshot("registering", p));
    const Delivered some = Drain(queue);
    all.pairs += some.pairs;
    all.skipped += some.skipped;
  }
  EXPECT_EQ(all.pairs, kPairs);
  EXPECT_EQ(all.skipped, 0u);
}

TEST(WatchQueue, ProgressSnapshotsOfOneStageMergeWithoutAGapAndStagesStay) {
  WatchQueue queue(kCapacity);
  for (uint32_t s = 0; s < 1000; ++s) queue.Push(Snapshot("fusing", 0));
  queue.Push(Snapshot("writing", 0));
  queue.Push(Snapshot("writing", 0));
  const Delivered delivered = Drain(queue);
  ASSERT_EQ(delivered.events.size(), 2u);
  EXPECT_EQ(delivered.events[0].job().stage(), "fusing");
  EXPECT_EQ(delivered.events[1].job().stage(), "writing");
  EXPECT_EQ(delivered.skipped, 0u);
}

}  // namespace
}  // namespace boicp::server
