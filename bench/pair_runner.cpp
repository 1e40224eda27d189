#include "pair_runner.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>

#include "evaluation.hpp"

namespace boicp::bench {
namespace {

ResultRow Timed(const std::string& method, const BenchPair& pair, const DatasetSettings& settings,
                const PairEvaluator& evaluator, int threads,
                const std::function<MethodOutput()>& run) {
  ResultRow row;
  row.dataset = pair.dataset;
  row.source = pair.source_name;
  row.target = pair.target_name;
  row.method = method;
  row.threads = threads;
  row.seed = pair.method_seed;
  row.perturb = PerturbationKindName(settings.perturb);
  row.voxel = settings.voxel;
  const auto start = std::chrono::steady_clock::now();
  try {
    const MethodOutput output = run();
    row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const PairMetrics metrics = evaluator.Evaluate(output.transform);
    row.voxel = output.voxel > 0.0 ? output.voxel : settings.voxel;
    row.iterations = output.iterations;
    row.source_points = output.source_points;
    row.target_points = output.target_points;
    row.evaluations = output.evaluations;
    row.rot_err_deg = metrics.rot_err_deg;
    row.trans_err_m = metrics.trans_err_m;
    row.mean_p2p_m = metrics.mean_p2p_m;
    row.overlap = metrics.overlap;
    row.success = metrics.success;
    row.confidence = output.confidence;
    row.icp_s = output.icp_s;
    row.model_s = output.model_s;
    row.features = output.features;
    row.attempts = output.attempts;
    row.answered_by = output.answered_by;
    row.retry_s = output.retry_s;
    for (const Attempt& a : output.attempt_details) {
      row.attempt_rows.push_back({AttemptKindName(a.kind), SearchModeName(a.mode), a.features,
                                  a.confidence, evaluator.Evaluate(a.transform).success, a.kept});
    }
  } catch (const std::exception& e) {
    // Open3D reports its errors as std::runtime_error: a failed method is a
    // result (it counts against the success rate), not the end of the run.
    row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    row.rot_err_deg = row.trans_err_m = row.mean_p2p_m = row.overlap = NAN;
    row.error = e.what();
  }
  return row;
}

}  // namespace

ResultRow RunOnPair(const std::string& method, const BenchPair& pair,
                    const DatasetSettings& settings, const PairEvaluator& evaluator, int threads,
                    bool quick) {
  const MethodInput input{pair.source, pair.target, settings, pair.method_seed, threads, quick};
  return Timed(method, pair, settings, evaluator, threads,
               [&] { return RunMethod(method, input); });
}

ResultRow RunBoConfigOnPair(const BoIcpConfig& config, const BenchPair& pair,
                            const DatasetSettings& settings, const PairEvaluator& evaluator,
                            bool quick) {
  const MethodInput input{pair.source, pair.target, settings, config.seed, config.threads, quick};
  ResultRow row = Timed("bo-C", pair, settings, evaluator, config.threads,
                        [&] { return RunBoIcpWithConfig(config, input); });
  row.seed = config.seed;
  return row;
}

std::string ProgressLine(const ResultRow& row, size_t index, size_t count) {
  std::string method = row.method;
  if (row.experiment != "suite") {
    char detail[96];
    std::snprintf(detail, sizeof(detail), " [%s voxel %.3g N %d]", row.experiment.c_str(),
                  row.voxel, row.iterations.value_or(0));
    method += detail;
  }
  char line[512];
  if (!row.error.empty()) {
    std::snprintf(line, sizeof(line), "[%s %zu/%zu] %-12s %7.2f s  FAILED: %s", row.dataset.c_str(),
                  index + 1, count, method.c_str(), row.wall_s, row.error.c_str());
  } else {
    std::snprintf(line, sizeof(line),
                  "[%s %zu/%zu] %-12s %7.2f s  rot %8.3f deg  trans %8.4f m  %s",
                  row.dataset.c_str(), index + 1, count, method.c_str(), row.wall_s,
                  row.rot_err_deg, row.trans_err_m, row.success ? "ok" : "miss");
  }
  return line;
}

}  // namespace boicp::bench
