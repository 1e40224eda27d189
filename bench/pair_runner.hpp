#pragma once
// Runs one method on one pair, timed, and turns the outcome into a row.

#include <string>

#include "bench_pairs.hpp"
#include "methods.hpp"
#include "pair_evaluator.hpp"
#include "result_row.hpp"

namespace boicp::bench {

/// Times RunMethod(method, ...) on the pair (wall clock around the whole
/// call) and scores its transform. A method that throws gives a row with its
/// message in `error`, NaN errors and success 0; the run goes on.
ResultRow RunOnPair(const std::string& method, const BenchPair& pair,
                    const DatasetSettings& settings, const PairEvaluator& evaluator, int threads,
                    bool quick);

/// Same, with an explicit BO config (the scaling study).
ResultRow RunBoConfigOnPair(const BoIcpConfig& config, const BenchPair& pair,
                            const DatasetSettings& settings, const PairEvaluator& evaluator,
                            bool quick);

/// "[kitti00 3/15] bo-C  4.21 s  rot 0.12 deg  trans 0.031 m  ok" for stderr.
std::string ProgressLine(const ResultRow& row, size_t index, size_t count);

}  // namespace boicp::bench
