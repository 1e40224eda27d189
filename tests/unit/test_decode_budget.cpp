// The decode budget: admission up to its limit, waits that end when bytes
// are released, at a stop request or at Close, and refusal of a request no
// release could ever admit. Waits are observed through waiting(), never timed.

#include "boicp/io/decode_budget.hpp"

#include <atomic>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/util/types.hpp"

namespace boicp {
namespace {

using ::testing::HasSubstr;

// Yields until `budget` has `count` callers waiting.
void AwaitWaiting(const DecodeBudget& budget, size_t count) {
  while (budget.waiting() != count) std::this_thread::yield();
}

TEST(DecodeBudget, AdmitsUpToItsLimitAndReleasesOnDestruction) {
  DecodeBudget budget(100);
  {
    const DecodeBudget::Lease a = budget.Acquire(60);
    const DecodeBudget::Lease b = budget.Acquire(40);
    EXPECT_EQ(a.bytes(), 60u);
    EXPECT_EQ(b.bytes(), 40u);
    EXPECT_EQ(budget.held_bytes(), 100u);
  }
  EXPECT_EQ(budget.held_bytes(), 0u);
  EXPECT_EQ(budget.Acquire(0).bytes(), 0u);
}

TEST(DecodeBudget, RefusesARequestOverTheWholeLimitAtOnceNamingTheFlag) {
  DecodeBudget budget(100u << 20);
  const DecodeBudget::Lease held = budget.Acquire(10);
  try {
    budget.Acquire((100u << 20) + 1);
    FAIL() << "expected LimitExceeded";
  } catch (const LimitExceeded& e) {
    EXPECT_THAT(e.what(), HasSubstr("over the decode budget of 100 MiB (--max-decode-mb)"));
  }
  EXPECT_EQ(budget.waiting(), 0u);
  EXPECT_EQ(budget.held_bytes(), 10u);
  EXPECT_THROW(DecodeBudget(0), std::invalid_argument);
}

TEST(DecodeBudget, AWaiterIsAdmittedWhenEnoughIsReleased) {
  DecodeBudget budget(100);
  std::optional<DecodeBudget::Lease> first = budget.Acquire(70);
  std::atomic<bool> admitted{false};
  std::thread waiter([&] {
    const DecodeBudget::Lease lease = budget.Acquire(50);
    admitted = true;
    EXPECT_EQ(budget.held_bytes(), 50u);
  });
  AwaitWaiting(budget, 1);
  EXPECT_FALSE(admitted);
  EXPECT_EQ(budget.held_bytes(), 70u);
  first.reset();
  waiter.join();
  EXPECT_TRUE(admitted);
  EXPECT_EQ(budget.held_bytes(), 0u);
}

TEST(DecodeBudget, WaitersAreAdmittedInArrivalOrder) {
  DecodeBudget budget(100);
  std::optional<DecodeBudget::Lease> held = budget.Acquire(100);
  std::vector<int> order;
  std::mutex order_mutex;
  std::atomic<bool> big_admitted{false};
  std::atomic<bool> release_big{false};
  std::thread big([&] {
    const DecodeBudget::Lease lease = budget.Acquire(100);
    {
      std::lock_guard<std::mutex> lock(order_mutex);
      order.push_back(1);
    }
    big_admitted = true;
    while (!release_big) std::this_thread::yield();
  });
  AwaitWaiting(budget, 1);
  std::thread small([&] {
    const DecodeBudget::Lease lease = budget.Acquire(1);
    std::lock_guard<std::mutex> lock(order_mutex);
    order.push_back(2);
  });
  AwaitWaiting(budget, 2);
  held.reset();
  // The small request would fit before the big one is admitted, but it
  // arrived later: it waits behind the big one, which then holds everything.
  while (!big_admitted) std::this_thread::yield();
  AwaitWaiting(budget, 1);
  release_big = true;
  big.join();
  small.join();
  EXPECT_EQ(order, (std::vector<int>{1, 2}));
}

TEST(DecodeBudget, AStopRequestEndsAWaitWithCancelledAndLeavesTheQueue) {
  DecodeBudget budget(100);
  const DecodeBudget::Lease held = budget.Acquire(100);
  std::atomic<bool> stop{false};
  std::atomic<bool> cancelled{false};
  std::thread waiter([&] {
    try {
      budget.Acquire(1, [&] { return stop.load(); });
    } catch (const Cancelled&) {
      cancelled = true;
    }
  });
  AwaitWaiting(budget, 1);
  stop = true;
  waiter.join();
  EXPECT_TRUE(cancelled);
  EXPECT_EQ(budget.waiting(), 0u);
  EXPECT_EQ(budget.held_bytes(), 100u);
}

TEST(DecodeBudget, CloseEndsEveryWaitAndLaterAcquires) {
  DecodeBudget budget(100);
  const DecodeBudget::Lease held = budget.Acquire(100);
  std::atomic<int> cancelled{0};
  std::vector<std::thread> waiters;
  for (int i = 0; i < 3; ++i) {
    waiters.emplace_back([&] {
      try {
        budget.Acquire(10);  // no stop request: only Close ends this wait
      } catch (const Cancelled&) {
        ++cancelled;
      }
    });
  }
  AwaitWaiting(budget, 3);
  budget.Close();
  for (std::thread& waiter : waiters) waiter.join();
  EXPECT_EQ(cancelled, 3);
  EXPECT_THROW(budget.Acquire(1), Cancelled);
  EXPECT_EQ(budget.held_bytes(), 100u);
}

TEST(DecodeBudget, AMovedLeaseIsReleasedOnce) {
  DecodeBudget budget(100);
  DecodeBudget::Lease a = budget.Acquire(30);
  DecodeBudget::Lease b = std::move(a);
  EXPECT_EQ(a.bytes(), 0u);  // NOLINT(bugprone-use-after-move): moved-from is empty
  EXPECT_EQ(budget.held_bytes(), 30u);
  DecodeBudget::Lease c = budget.Acquire(20);
  c = std::move(b);  // releases c's 20
  EXPECT_EQ(budget.held_bytes(), 30u);
  c = DecodeBudget::Lease();
  EXPECT_EQ(budget.held_bytes(), 0u);
}

}  // namespace
}  // namespace boicp
