// boicp-bench: BO-ICP against its baselines on reference pairs (issue #3).
// Exit codes: 0 done, 2 bad command line or unreadable input.

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <set>

#include <open3d/utility/Logging.h>

#include "bench_options.hpp"
#include "bench_pairs.hpp"
#include "bench_run.hpp"
#include "thread_budget.hpp"

namespace {

constexpr int kBadInput = 2;

// Reads every CSV up front, so a typo fails in a second, not after an hour.
std::vector<boicp::bench::DatasetPairs> ReadDatasets(const boicp::bench::BenchOptions& options) {
  using boicp::bench::UsageError;
  std::vector<boicp::bench::DatasetPairs> datasets;
  std::set<std::string> names;
  for (const std::string& csv : options.pairs_csvs) {
    datasets.push_back(boicp::bench::ReadDataset(csv, options.overrides));
  }
  if (options.synthetic_pairs > 0) {
    datasets.push_back(boicp::bench::SyntheticDataset(options.synthetic_pairs, options.overrides));
  }
  for (const auto& dataset : datasets) {
    if (!names.insert(dataset.settings.name).second) {
      throw UsageError("dataset '" + dataset.settings.name + "' selected twice");
    }
  }
  for (const std::string& name : options.scaling_datasets) {
    if (names.count(name) == 0) throw UsageError("--scaling: dataset '" + name + "' not selected");
  }
  return datasets;
}

// libgomp reads OMP_WAIT_POLICY once, when it loads. Its default spins at
// every barrier, and on a shared 2-core machine a spinning thread starves the
// team member it waits for: ICP's short parallel loops then ran 5-10x slower
// with 2 threads than with 1. So unless the caller chose a policy, restart
// once with PASSIVE (threads sleep at barriers); the summary states it.
void RestartWithPassiveWaitPolicy(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;
  ::setenv("OMP_WAIT_POLICY", "PASSIVE", 1);
  ::execv("/proc/self/exe", argv);  // returns only on failure: then run as we are
}

}  // namespace

int main(int argc, char** argv) {
  RestartWithPassiveWaitPolicy(argv);
  boicp::bench::BenchOptions options;
  std::vector<boicp::bench::DatasetPairs> datasets;
  try {
    options = boicp::bench::ParseBenchOptions(argc, argv);
    if (options.help) {
      std::cout << boicp::bench::UsageText();
      return 0;
    }
    // Before anything touches OpenMP or Open3D.
    boicp::bench::ApplyThreadBudget(options.threads);
    open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
    datasets = ReadDatasets(options);
    std::filesystem::create_directories(options.out_dir);
  } catch (const std::exception& e) {
    std::cerr << "boicp-bench: " << e.what() << std::endl;
    return kBadInput;
  }
  return boicp::bench::RunBenchmark(options, datasets);
}
