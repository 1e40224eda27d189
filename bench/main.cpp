// boicp-bench: BO-ICP against its baselines on reference pairs.
// Exit codes: 0 done, 2 bad command line or unreadable input.

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

}  // namespace

int main(int argc, char** argv) {
  boicp::bench::BenchOptions options;
  std::vector<boicp::bench::DatasetPairs> datasets;
  try {
    options = boicp::bench::ParseBenchOptions(argc, argv);
    if (options.help) {
      std::cout << options.usage;
      return 0;
    }
    // Before anything touches OpenMP or Open3D.
    boicp::bench::ApplyThreadBudget(options.threads);
    // libgomp reads its wait policy once, before main, and no call changes
    // it; its default spins at barriers, and on a shared machine a spinning
    // thread starves the one it waits for, so the Open3D baselines would be
    // timed slower than they are.
    if (std::getenv("OMP_WAIT_POLICY") == nullptr) {
      std::cerr << "boicp-bench: OMP_WAIT_POLICY is unset, so the Open3D baselines' OpenMP "
                   "threads spin while they wait and may be timed slow on a shared machine; "
                   "set OMP_WAIT_POLICY=PASSIVE (bench/run.sh does)\n";
    }
    open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
    datasets = ReadDatasets(options);
    std::filesystem::create_directories(options.out_dir);
  } catch (const std::exception& e) {
    std::cerr << "boicp-bench: " << e.what() << std::endl;
    return kBadInput;
  }
  return boicp::bench::RunBenchmark(options, datasets);
}
