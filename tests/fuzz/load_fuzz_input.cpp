#include "load_fuzz_input.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "boicp/io/bag_reader.hpp"

namespace boicp::fuzz {
namespace {

// One file per process, overwritten by every input: libFuzzer runs inputs one
// at a time, and parallel jobs (-jobs=N) are separate processes.
std::string ScratchPath(const std::string& extension) {
  return (std::filesystem::temp_directory_path() /
          ("boicp-fuzz-" + std::to_string(::getpid()) + extension))
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

// Small, so that inputs declaring big chunks are refused rather than the run
// spent allocating and zeroing them.
constexpr uint64_t kBagMessageLimit = uint64_t{1} << 20;

void ReadWholeBag(BagReader& bag) {
  bag.TimeRange();
  for (const BagTopic& topic : bag.Topics()) {
    for (const BagMessageRef& message : bag.Messages(topic.name)) {
      try {
        if (bag.Read(message).size() > message.size) {
          std::fprintf(stderr, "Read returned more bytes than Messages declared\n");
          std::abort();
        }
      } catch (const InputError&) {
      }
    }
  }
}

}  // namespace

void ReadFuzzBag(const uint8_t* data, size_t size, const std::string& extension) {
  const std::string path = ScratchPath(extension);
  WriteAll(path, data, size);
  BagLimits limits;
  limits.max_message_bytes = kBagMessageLimit;
  try {
    ReadWholeBag(*OpenBag(path, limits));
  } catch (const InputError&) {
    // Malformed input refused with a message: the expected outcome.
  }
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
}

void LoadFuzzBytes(const uint8_t* data, size_t size, const LoadOptions& options) {
  const std::string path = ScratchPath("." + CloudFormatName(options.format));
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
