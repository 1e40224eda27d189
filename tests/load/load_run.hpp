#pragma once
// A whole load run against a boicpd this process starts on loopback: a
// warm-up under the same load, then the measured window, with the daemon's
// resident memory read while it is idle before, between and after.

#include <string>
#include <vector>

#include "load_client.hpp"
#include "load_options.hpp"
#include "process_memory.hpp"

namespace boicp::load {

struct LoadFigures {
  double window_s = 0.0;  // the main phase's submission window
  double main_s = 0.0;    // main phase, from its start until its last job ended
  ClientTotals warmup, main;
  ProcessMemory started;            // idle, before any request
  ProcessMemory warmed;             // idle, after the warm-up
  ProcessMemory after;              // idle, after the main phase; peak_rss_mb is the run's peak
  std::vector<double> busy_rss_mb;  // VmRSS every busy_sample_s during the main phase
  double busy_sample_s = 0.0;
  std::string load_average_start, load_average_end;  // /proc/loadavg: the machine is shared
  int daemon_exit = -1;                     // exit code after SIGTERM; -1 when it did not exit
  std::string daemon_log;                   // path of the daemon's log
  std::vector<std::string> harness_errors;  // the run itself went wrong (daemon gone, ...)
};

/// Starts the daemon in `work_dir`, runs both phases and stops it again
/// (SIGTERM, then SIGKILL if it hangs). Throws only when the daemon does not start.
LoadFigures RunLoad(const LoadOptions& options, const std::string& work_dir);

}  // namespace boicp::load
