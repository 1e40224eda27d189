// ParallelFor and ParallelForRanges: every index once, and the same outcome
// for any thread count.

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "boicp/util/parallel_for.hpp"

namespace boicp {
namespace {

class ParallelForThreads : public ::testing::TestWithParam<int> {};

TEST_P(ParallelForThreads, CallsEveryIndexExactlyOnce) {
  std::vector<std::atomic<int>> calls(37);
  ParallelFor(calls.size(), GetParam(), [&](size_t i) { ++calls[i]; });
  for (size_t i = 0; i < calls.size(); ++i) EXPECT_EQ(calls[i].load(), 1) << "index " << i;
}

TEST_P(ParallelForThreads, RethrowsTheLowestFailingIndexAfterRunningTheRest) {
  std::atomic<int> finished{0};
  try {
    ParallelFor(20, GetParam(), [&](size_t i) {
      if (i == 13 || i == 5) throw std::runtime_error("task " + std::to_string(i));
      ++finished;
    });
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "task 5");
  }
  EXPECT_EQ(finished.load(), 18);
}

TEST_P(ParallelForThreads, NothingToDoIsFine) {
  ParallelFor(0, GetParam(), [](size_t) { FAIL() << "no task expected"; });
}

TEST_P(ParallelForThreads, RangesCoverEveryIndexExactlyOnce) {
  std::vector<std::atomic<int>> calls(10007);
  ParallelForRanges(calls.size(), GetParam(), [&](size_t begin, size_t end) {
    ASSERT_LT(begin, end);
    for (size_t i = begin; i < end; ++i) ++calls[i];
  });
  for (size_t i = 0; i < calls.size(); ++i) ASSERT_EQ(calls[i].load(), 1) << "index " << i;
  ParallelForRanges(0, GetParam(), [](size_t, size_t) { FAIL() << "no range expected"; });
}

// 0 counts as one thread; 8 is more threads than tasks in some cases.
INSTANTIATE_TEST_SUITE_P(Threads, ParallelForThreads, ::testing::Values(0, 1, 2, 8));

}  // namespace
}  // namespace boicp
