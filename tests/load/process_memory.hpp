#pragma once
// A process's resident memory, from /proc/PID/status.

#include <sys/types.h>

namespace boicp::load {

struct ProcessMemory {
  double rss_mb = 0.0;       // VmRSS: resident now
  double peak_rss_mb = 0.0;  // VmHWM: the most ever resident
};

/// Reads VmRSS and VmHWM of `pid` (MiB). Throws std::runtime_error when the
/// process is gone or the fields are missing.
ProcessMemory ReadProcessMemory(pid_t pid);

}  // namespace boicp::load
