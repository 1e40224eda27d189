#pragma once
// Coarse-grained parallelism for independent tasks that each take
// milliseconds or more (whole ICP runs), on plain std::threads: no pool
// outlives the call and no idle thread spins while the caller's other work
// (or another registration in the daemon) needs the core.

#include <cstddef>
#include <functional>

namespace boicp {

/// Calls task(i) once for every i in [0, count), on min(threads, count)
/// threads, the calling thread among them. Tasks must be independent: each
/// writes only its own outputs. If tasks throw, the exception of the lowest
/// index is rethrown after every thread has finished, so the outcome does not
/// depend on the thread count or on scheduling. threads < 1 counts as 1.
void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& task);

}  // namespace boicp
