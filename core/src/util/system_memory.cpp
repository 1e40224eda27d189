#include "boicp/util/system_memory.hpp"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>

namespace boicp {
namespace {

// A cgroup limit file's value, or 0 when absent or "max" (no limit).
uint64_t ReadLimit(const char* path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text.empty() || text.find_first_not_of("0123456789") != std::string::npos) {
    return 0;
  }
  try {
    return std::stoull(text);
  } catch (const std::exception&) {
    return 0;  // out of range: no limit worth the name
  }
}

}  // namespace

uint64_t UsableMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_size = sysconf(_SC_PAGE_SIZE);
  uint64_t usable = pages > 0 && page_size > 0
                        ? static_cast<uint64_t>(pages) * static_cast<uint64_t>(page_size)
                        : 0;
  for (const char* path :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    const uint64_t limit = ReadLimit(path);
    if (limit > 0 && (usable == 0 || limit < usable)) usable = limit;
  }
  return usable;
}

uint64_t DefaultFusionLimitMb() { return std::max<uint64_t>(UsableMemoryBytes() / 2 >> 20, 1); }

}  // namespace boicp
