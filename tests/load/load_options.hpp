#pragma once
// What one load run does: how many clients, for how long, how big their
// batches are, how the daemon is started and what counts as too much memory.

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

namespace boicp::load {

struct LoadOptions {
  int clients = 20;
  double warmup_seconds = 30.0;  // the same load first, so memory has settled before it is measured
  double seconds = 60.0;         // submission window; jobs submitted in it are then waited for
  double drain_seconds = 300.0;  // longest wait for those jobs after the window
  std::string out;               // figures file; empty = stdout only
  uint64_t seed = 1;             // every random choice derives from it
  int scans_per_batch = 3;
  int points_per_scan = 3000;  // random subset of a generated scan, so every upload is new bytes
  int drive_scans = 12;        // length of the generated drive the batches are cut from
  int workers = 2;             // boicpd --workers
  int jobs = 2;                // boicpd --jobs
  double poll_min_ms = 100.0;  // each client polls its job with a uniform pause in [min, max]
  double poll_max_ms = 300.0;
  double max_rss_growth_mb = 16.0;  // idle RSS after the run minus idle RSS after the warm-up
  std::string work_dir;             // data directory and daemon log; empty = a fresh temp folder
  bool keep_work_dir = false;
};

/// Registers the flags on `app`, writing into `options`.
void AddLoadOptions(CLI::App& app, LoadOptions& options);

/// Throws std::invalid_argument naming the first flag out of range.
void ValidateLoadOptions(const LoadOptions& options);

}  // namespace boicp::load
