#include "machine_info.hpp"

#include <unistd.h>

#include <fstream>

#include <open3d/Open3DConfig.h>

#include "boicp/util/text.hpp"

namespace boicp::bench {
namespace {

std::string CpuModel() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const size_t colon = line.find(':');
    if (colon != std::string::npos) return Trim(line.substr(colon + 1));
  }
  return "unknown";
}

std::string LoadAverage() {
  std::ifstream loadavg("/proc/loadavg");
  std::string one, five, fifteen;
  if (!(loadavg >> one >> five >> fifteen)) return "unknown";
  return one + " " + five + " " + fifteen;
}

}  // namespace

MachineInfo DescribeMachine() {
  MachineInfo info;
  info.logical_cores = static_cast<int>(::sysconf(_SC_NPROCESSORS_ONLN));
  info.cpu_model = CpuModel();
  info.load_average = LoadAverage();
  info.open3d_version = OPEN3D_VERSION;
  return info;
}

}  // namespace boicp::bench
