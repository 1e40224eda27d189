// libFuzzer harness: arbitrary bytes as a ROS 1 .bag file through OpenBag,
// then every topic's messages read back. InputError is the documented
// failure; anything else (or a crash inside rosbag_storage) is a finding.

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "boicp/io/bag_reader.hpp"
#include "boicp/util/types.hpp"

namespace {

// One file per process, overwritten by every input (see load_fuzz_input.cpp).
std::string ScratchPath() {
  return (std::filesystem::temp_directory_path() /
          ("boicp-fuzz-" + std::to_string(::getpid()) + ".bag"))
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

// Reads every message; a message that fails is skipped, as a caller would.
void ReadEverything(boicp::BagReader& bag, const boicp::BagLimits& limits) {
  bag.TimeRange();
  for (const boicp::BagTopic& topic : bag.Topics()) {
    for (const boicp::BagMessageRef& message : bag.Messages(topic.name)) {
      try {
        if (bag.Read(message).size() > limits.max_message_bytes) {
          std::fprintf(stderr, "Read returned more than max_message_bytes\n");
          std::abort();
        }
      } catch (const boicp::InputError&) {
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = ScratchPath();
  WriteAll(path, data, size);
  boicp::BagLimits limits;
  limits.max_message_bytes = 1 << 20;  // small, so a lying size is refused, not allocated
  try {
    ReadEverything(*boicp::OpenBag(path, limits), limits);
  } catch (const boicp::InputError&) {
    // Malformed input refused with a message: the expected outcome.
  }
  return 0;
}
