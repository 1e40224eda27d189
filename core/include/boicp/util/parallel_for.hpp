#pragma once
// The one way the engine runs work in parallel: oneTBB loops inside an arena
// of an explicit size, so a caller's thread count is a hard cap (the daemon
// runs several registrations side by side) and no idle thread spins.

#include <cstddef>
#include <functional>

namespace boicp {

/// The cores this process may run on (its CPU affinity mask, which a
/// container's cpuset narrows), at least 1: the default thread count of every
/// binary.
int AvailableCores();

/// Calls task(i) once for every i in [0, count), on at most `threads`
/// threads. For coarse tasks (an ICP run each). Tasks must be independent:
/// each writes only its own outputs. If tasks throw, the exception of the
/// lowest index is rethrown after every task has run, so the outcome does not
/// depend on the thread count or on scheduling. threads < 1 counts as 1.
void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& task);

/// Calls body(begin, end) on disjoint ranges that cover [0, count), on at
/// most `threads` threads. For fine-grained loops (one nearest-neighbour query
/// an index) where a call per index would cost more than the work. The body
/// must write only the outputs of its own indices and must not throw. With
/// threads <= 1 it is one call, body(0, count), on the calling thread.
void ParallelForRanges(size_t count, int threads,
                       const std::function<void(size_t begin, size_t end)>& body);

}  // namespace boicp
