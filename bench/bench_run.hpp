#pragma once
// The benchmark loop: every selected method on every selected pair, then the
// scaling study, writing results.csv after each pair and summary.md at the end.

#include <vector>

#include "bench_options.hpp"
#include "bench_pairs.hpp"

namespace boicp::bench {

/// Runs the benchmark into options.out_dir (which must exist). Returns the
/// process exit code: 0, or 2 when a pair's files cannot be loaded.
int RunBenchmark(const BenchOptions& options, const std::vector<DatasetPairs>& datasets);

}  // namespace boicp::bench
