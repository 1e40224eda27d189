#include "bench_run.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <iostream>

#include "boicp/util/atomic_file.hpp"
#include "machine_info.hpp"
#include "methods.hpp"
#include "pair_evaluator.hpp"
#include "pair_runner.hpp"
#include "scaling.hpp"
#include "summary.hpp"

namespace boicp::bench {
namespace {

std::string NowUtc() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S", &utc);
  return text;
}

class BenchRun {
 public:
  BenchRun(const BenchOptions& options, const std::vector<DatasetPairs>& datasets)
      : options_(options), datasets_(datasets), start_(std::chrono::steady_clock::now()) {
    info_.machine = DescribeMachine();
    info_.threads = options.threads;
    info_.seed = options.seed;
    info_.quick = options.quick;
    info_.command_line = options.command_line;
    info_.started_utc = NowUtc();
    for (const DatasetPairs& d : datasets) info_.datasets.push_back(d.settings);
    info_.method_lines = DescribeMethods(options.methods, options.quick);
    if (!options.scaling_datasets.empty()) {
      info_.scaling_line = DescribeScaling(options.quick);
    }
  }

  int Run() {
    std::cout << "boicp-bench\n" << FormatRunConditions(info_) << std::endl;
    for (const DatasetPairs& dataset : datasets_) {
      const size_t count = options_.scaling_only ? 0 : PairCount(dataset);
      for (size_t index = 0; index < count; ++index) {
        const BenchPair pair = Load(dataset, index);
        const PairEvaluator evaluator(pair, dataset.settings);
        for (const std::string& method : options_.methods) {
          Add(RunOnPair(method, pair, dataset.settings, evaluator, options_.threads,
                        options_.quick),
              index, count);
        }
        WriteResults();
      }
      if (std::find(options_.scaling_datasets.begin(), options_.scaling_datasets.end(),
                    dataset.settings.name) != options_.scaling_datasets.end()) {
        const BenchPair pair = Load(dataset, 0);
        RunScaling(pair, dataset.settings, options_.threads, options_.quick,
                   [&](const ResultRow& row) { Add(row, 0, 1); });
        WriteResults();
      }
    }
    WriteResults();
    info_.wall_s = Elapsed();
    info_.load_average_end = DescribeMachine().load_average;
    const std::string summary = FormatSummary(info_, rows_);
    WriteTextFileAtomically(Path("summary.md"), summary);
    std::cout << "\n"
              << summary << "\nwrote " << Path("results.csv") << " and " << Path("summary.md")
              << std::endl;
    return 0;
  }

 private:
  size_t PairCount(const DatasetPairs& dataset) const {
    const size_t all = dataset.references.size();
    return options_.max_pairs > 0 ? std::min(all, static_cast<size_t>(options_.max_pairs)) : all;
  }

  BenchPair Load(const DatasetPairs& dataset, size_t index) const {
    return dataset.settings.entry == "synthetic" ? MakeSyntheticPair(dataset, index, options_.seed)
                                                 : LoadPair(dataset, index, options_.seed);
  }

  void Add(ResultRow row, size_t index, size_t count) {
    std::cerr << ProgressLine(row, index, count) << std::endl;
    rows_.push_back(std::move(row));
  }

  void WriteResults() const {
    WriteTextFileAtomically(Path("results.csv"), FormatResultsCsv(rows_));
    WriteTextFileAtomically(Path("attempts.csv"), FormatAttemptsCsv(rows_));
  }

  std::string Path(const std::string& name) const {
    return (std::filesystem::path(options_.out_dir) / name).string();
  }

  double Elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

  const BenchOptions& options_;
  const std::vector<DatasetPairs>& datasets_;
  std::chrono::steady_clock::time_point start_;
  RunInfo info_;
  std::vector<ResultRow> rows_;
};

}  // namespace

int RunBenchmark(const BenchOptions& options, const std::vector<DatasetPairs>& datasets) {
  try {
    return BenchRun(options, datasets).Run();
  } catch (const InputError& e) {
    std::cerr << "boicp-bench: " << e.what() << std::endl;
    return 2;
  }
}

}  // namespace boicp::bench
