#include "load_run.hpp"

#include <signal.h>

#include <fstream>
#include <thread>

#include "daemon_process.hpp"
#include "memory_sampler.hpp"

namespace boicp::load {
namespace {

// Time for a daemon with no open job to finish its bookkeeping before its
// memory is read; a pause, never an assertion.
constexpr std::chrono::seconds kSettle{2};
constexpr double kStopTimeoutS = 30.0;
constexpr std::chrono::seconds kBusySampleInterval{10};

// Seeds: the drive and each phase's clients draw from separate streams.
enum SeedStream : int { kDriveSeed = 1, kWarmupSeed = 2, kMainSeed = 3 };

Clock::duration FromSeconds(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// Every client submits for `window_s`; then their open jobs get up to
// options.drain_seconds to end.
ClientTotals RunPhase(const LoadOptions& options, const std::string& address,
                      const BatchScans& scans, SeedStream stream, double window_s) {
  const Clock::time_point submit_until = Clock::now() + FromSeconds(window_s);
  const Clock::time_point give_up_at = submit_until + FromSeconds(options.drain_seconds);
  std::vector<ClientPlan> plans(static_cast<size_t>(options.clients));
  std::vector<ClientTotals> results(plans.size());
  std::vector<std::thread> threads;
  for (size_t i = 0; i < plans.size(); ++i) {
    plans[i] = {address, static_cast<int>(i), MixSeed(options.seed, stream, static_cast<int>(i)),
                submit_until, give_up_at};
    threads.emplace_back([&, i] { results[i] = RunLoadClient(plans[i], options, scans); });
  }
  ClientTotals totals;
  for (size_t i = 0; i < threads.size(); ++i) {
    threads[i].join();
    totals.Merge(results[i]);
  }
  return totals;
}

// The 1, 5 and 15 minute load averages, as /proc/loadavg has them.
std::string LoadAverage() {
  std::ifstream file("/proc/loadavg");
  std::string one, five, fifteen;
  file >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

LoadFigures RunLoad(const LoadOptions& options, const std::string& work_dir) {
  LoadFigures figures;
  figures.load_average_start = LoadAverage();
  figures.daemon_log = work_dir + "/boicpd.log";
  test::DaemonProcess daemon(
      // Every client may upload at once: the load measured is the daemon's
      // work, not its upload limit (Limits.UploadsInFlight tests that).
      {"--data-dir", work_dir + "/data", "--workers", std::to_string(options.workers), "--jobs",
       std::to_string(options.jobs), "--registration-threads", "1", "--max-concurrent-uploads",
       std::to_string(options.clients)},
      figures.daemon_log);
  const auto memory = [&](ProcessMemory& into, const char* when) {
    std::this_thread::sleep_for(kSettle);
    try {
      into = ReadProcessMemory(daemon.pid());
    } catch (const std::exception& e) {
      figures.harness_errors.push_back(std::string("memory ") + when + ": " + e.what());
    }
  };
  memory(figures.started, "at start");

  const BatchScans scans(options.drive_scans, MixSeed(options.seed, kDriveSeed));
  figures.warmup = RunPhase(options, daemon.address(), scans, kWarmupSeed, options.warmup_seconds);
  memory(figures.warmed, "after the warm-up");

  const auto main_start = Clock::now();
  figures.window_s = options.seconds;
  figures.busy_sample_s = static_cast<double>(kBusySampleInterval.count());
  MemorySampler busy_memory(daemon.pid(), kBusySampleInterval);
  figures.main = RunPhase(options, daemon.address(), scans, kMainSeed, options.seconds);
  figures.busy_rss_mb = busy_memory.Stop();
  figures.main_s = Seconds(Clock::now() - main_start);
  memory(figures.after, "after the run");
  figures.load_average_end = LoadAverage();

  daemon.Signal(SIGTERM);
  figures.daemon_exit = daemon.Wait(kStopTimeoutS);
  return figures;  // ~DaemonProcess kills a daemon that did not stop
}

}  // namespace boicp::load
