#pragma once
// What the numbers were measured on: they mean little without it.

#include <string>

namespace boicp::bench {

struct MachineInfo {
  int logical_cores = 0;     // online processors (nproc)
  std::string cpu_model;     // "model name" of /proc/cpuinfo, or "unknown"
  std::string load_average;  // first three fields of /proc/loadavg at the start
  std::string open3d_version;
};

MachineInfo DescribeMachine();

}  // namespace boicp::bench
