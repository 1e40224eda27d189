#include "load_options.hpp"

#include <stdexcept>

namespace boicp::load {

void AddLoadOptions(CLI::App& app, LoadOptions& o) {
  app.add_option("--clients", o.clients, "Concurrent clients, each with its own channel")
      ->capture_default_str();
  app.add_option("--warmup-seconds", o.warmup_seconds,
                 "Submission window of the warm-up (the same load, not in the figures but "
                 "the memory baseline)")
      ->capture_default_str();
  app.add_option("--seconds", o.seconds, "Submission window in seconds")->capture_default_str();
  app.add_option("--drain-seconds", o.drain_seconds,
                 "Longest wait for the jobs still open when the window closes")
      ->capture_default_str();
  app.add_option("--out", o.out, "Write the figures to this file (also printed)");
  app.add_option("--seed", o.seed, "Seed of every random choice")->capture_default_str();
  app.add_option("--scans-per-batch", o.scans_per_batch, "Consecutive scans in each batch")
      ->capture_default_str();
  app.add_option("--points-per-scan", o.points_per_scan, "Points kept of each generated scan")
      ->capture_default_str();
  app.add_option("--drive-scans", o.drive_scans, "Scans of the generated drive")
      ->capture_default_str();
  app.add_option("--workers", o.workers, "boicpd --workers")->capture_default_str();
  app.add_option("--jobs", o.jobs, "boicpd --jobs")->capture_default_str();
  app.add_option("--poll-min-ms", o.poll_min_ms, "Shortest pause between a client's polls")
      ->capture_default_str();
  app.add_option("--poll-max-ms", o.poll_max_ms, "Longest pause between a client's polls")
      ->capture_default_str();
  app.add_option("--max-rss-growth-mb", o.max_rss_growth_mb,
                 "Fail when the idle RSS after the run exceeds the idle RSS after the warm-up "
                 "by more than this")
      ->capture_default_str();
  app.add_option("--work-dir", o.work_dir,
                 "Folder for the data directory and the daemon log (default: a fresh temp one)");
  app.add_flag("--keep-work-dir", o.keep_work_dir, "Keep the work folder (always kept on failure)");
}

void ValidateLoadOptions(const LoadOptions& o) {
  auto require = [](bool ok, const char* message) {
    if (!ok) throw std::invalid_argument(message);
  };
  require(o.clients >= 1 && o.clients <= 1000, "--clients must be in 1..1000");
  require(o.seconds > 0.0, "--seconds must be > 0");
  require(o.warmup_seconds > 0.0, "--warmup-seconds must be > 0");
  require(o.drain_seconds > 0.0, "--drain-seconds must be > 0");
  require(o.scans_per_batch >= 2, "--scans-per-batch must be at least 2");
  require(o.drive_scans >= o.scans_per_batch, "--drive-scans must be >= --scans-per-batch");
  require(o.points_per_scan >= 100, "--points-per-scan must be at least 100");
  require(o.workers >= 1 && o.jobs >= 1, "--workers and --jobs must be at least 1");
  require(o.poll_min_ms >= 0.0 && o.poll_max_ms >= o.poll_min_ms,
          "--poll-min-ms must be >= 0 and <= --poll-max-ms");
  require(o.max_rss_growth_mb > 0.0, "--max-rss-growth-mb must be > 0");
}

}  // namespace boicp::load
