#include "process_memory.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace boicp::load {

ProcessMemory ReadProcessMemory(pid_t pid) {
  const std::string path = "/proc/" + std::to_string(pid) + "/status";
  std::ifstream status(path);
  if (!status) throw std::runtime_error("cannot read " + path + " (did the process exit?)");
  ProcessMemory memory;
  bool have_rss = false, have_hwm = false;
  std::string line;
  while (std::getline(status, line)) {
    std::istringstream fields(line);
    std::string key;
    double kib = 0.0;
    if (!(fields >> key >> kib)) continue;
    if (key == "VmRSS:") {
      memory.rss_mb = kib / 1024.0;
      have_rss = true;
    } else if (key == "VmHWM:") {
      memory.peak_rss_mb = kib / 1024.0;
      have_hwm = true;
    }
  }
  if (!have_rss || !have_hwm)
    throw std::runtime_error(path + " has no VmRSS/VmHWM (the process has exited)");
  return memory;
}

}  // namespace boicp::load
