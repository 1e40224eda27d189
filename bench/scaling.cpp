#include "scaling.hpp"

#include "dataset_config.hpp"
#include "pair_evaluator.hpp"
#include "pair_runner.hpp"

namespace boicp::bench {

ScalingPlan PlanScaling(bool quick) {
  if (quick) return {{2.0, 1.75, 1.5, 1.25}, {2, 4, 6, 8}};
  return {{2.0, 1.5, 1.0, 0.75}, {10, 30, 60, 120}};
}

std::vector<ResultRow> RunScaling(const BenchPair& pair, const DatasetSettings& settings,
                                  int threads, bool quick,
                                  const std::function<void(const ResultRow&)>& on_row) {
  const ScalingPlan plan = PlanScaling(quick);
  const PairEvaluator evaluator(pair, settings);
  const MethodInput input{pair.source, pair.target, settings, pair.method_seed, threads, quick};
  const BoIcpConfig base = DatasetBoConfig("C", input);
  std::vector<ResultRow> rows;
  auto run = [&](const BoIcpConfig& config, const std::string& experiment) {
    ResultRow row = RunBoConfigOnPair(config, pair, settings, evaluator, quick);
    row.experiment = experiment;
    on_row(row);
    rows.push_back(row);
  };
  for (const char* experiment : {"scaling-voxel", "scaling-voxel-all"}) {
    for (double factor : plan.voxel_factors) {
      BoIcpConfig config = base;
      config.voxel = base.voxel * factor;
      if (std::string(experiment) == "scaling-voxel-all") {
        config.evaluation_points = 0;
        config.coarse_icp_points = 0;
      }
      run(config, experiment);
    }
  }
  for (int iterations : plan.iterations) {
    BoIcpConfig config = base;
    config.iterations = iterations;
    run(config, "scaling-iterations");
  }
  return rows;
}

std::string DescribeScaling(bool quick) {
  const ScalingPlan plan = PlanScaling(quick);
  std::string voxels, iterations;
  for (double f : plan.voxel_factors) {
    voxels += (voxels.empty() ? "" : ", ") + std::to_string(f).substr(0, 4);
  }
  for (int n : plan.iterations) {
    iterations += (iterations.empty() ? "" : ", ") + std::to_string(n);
  }
  return "bo-C on the first pair; voxel x (" + voxels +
         ") of the dataset's, with the default 2000-point evaluation subsample "
         "(scaling-voxel) and with every point (scaling-voxel-all); N = (" +
         iterations + ") per stage with N_r = " + (quick ? "10" : "30") + " (scaling-iterations)";
}

}  // namespace boicp::bench
