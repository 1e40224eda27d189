#include "load_fuzz_input.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace boicp::fuzz {
namespace {

// One file per process, overwritten by every input: libFuzzer runs inputs one
// at a time, and parallel jobs (-jobs=N) are separate processes.
std::string ScratchPath(CloudFormat format) {
  return (std::filesystem::temp_directory_path() /
          ("boicp-fuzz-" + std::to_string(::getpid()) + "." + CloudFormatName(format)))
      .string();
}

void WriteAll(const std::string& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz harness: cannot write %s\n", path.c_str());
    std::abort();
  }
}

void RequireSaneCloud(const LoadedCloud& cloud) {
  if (cloud.points.empty()) {
    std::fprintf(stderr, "LoadPointCloud returned an empty cloud without throwing\n");
    std::abort();
  }
  for (const Point& p : cloud.points) {
    if (!p.allFinite()) {
      std::fprintf(stderr, "LoadPointCloud returned a non-finite point\n");
      std::abort();
    }
  }
}

}  // namespace

void LoadFuzzBytes(const uint8_t* data, size_t size, const LoadOptions& options) {
  const std::string path = ScratchPath(options.format);
  WriteAll(path, data, size);
  try {
    RequireSaneCloud(LoadPointCloud(path, options));
  } catch (const InputError&) {
    // Malformed input refused with a message: the expected outcome.
  }
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
}

}  // namespace boicp::fuzz
