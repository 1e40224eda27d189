#include "boicp/util/parallel_for.hpp"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace boicp {
namespace {

// Runs `loop` in an arena of `threads` slots, the calling thread among them.
template <typename Loop>
void InArena(int threads, const Loop& loop) {
  tbb::task_arena arena(threads);
  arena.execute(loop);
}

// The ThreadSanitizer build cannot see oneTBB's synchronisation (Debian's
// libtbb is not instrumented), so there the same tasks run on plain threads,
// each taking an equal block of indices, and TSan checks the task bodies.
void OnPlainThreads(size_t count, int threads, const std::function<void(size_t, size_t)>& body) {
  const size_t workers = std::min<size_t>(count, static_cast<size_t>(threads));
  std::vector<std::thread> pool;
  for (size_t w = 1; w < workers; ++w) {
    pool.emplace_back([&, w] { body(count * w / workers, count * (w + 1) / workers); });
  }
  body(0, count / workers);
  for (std::thread& thread : pool) thread.join();
}

#ifdef BOICP_PLAIN_THREADS
constexpr bool kPlainThreads = true;
#else
constexpr bool kPlainThreads = false;
#endif

}  // namespace

int AvailableCores() { return std::max(1, tbb::info::default_concurrency()); }

void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& task) {
  if (count == 0) return;
  std::vector<std::exception_ptr> errors(count);
  const auto run = [&](size_t i) {
    try {
      task(i);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  };
  if (threads <= 1 || count == 1) {
    for (size_t i = 0; i < count; ++i) run(i);
  } else if (kPlainThreads) {
    OnPlainThreads(count, threads, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) run(i);
    });
  } else {
    // One index a task: each takes milliseconds, so balance beats batching.
    InArena(threads, [&] {
      tbb::parallel_for(
          tbb::blocked_range<size_t>(0, count, 1),
          [&](const tbb::blocked_range<size_t>& range) {
            for (size_t i = range.begin(); i < range.end(); ++i) run(i);
          },
          tbb::simple_partitioner());
    });
  }
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

void ParallelForRanges(size_t count, int threads,
                       const std::function<void(size_t begin, size_t end)>& body) {
  if (count == 0) return;
  if (threads <= 1) {
    body(0, count);
    return;
  }
  if (kPlainThreads) {
    OnPlainThreads(count, threads, body);
    return;
  }
  // One contiguous block a thread: the work per index is even, and a static
  // split keeps each thread's points (and their cache lines) its own.
  InArena(threads, [&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, count),
        [&](const tbb::blocked_range<size_t>& range) { body(range.begin(), range.end()); },
        tbb::static_partitioner());
  });
}

}  // namespace boicp
