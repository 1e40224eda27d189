// libFuzzer harness: arbitrary bytes as a ROS 2 .db3 bag (rosbag2's sqlite3
// storage), read whole through OpenBag (topics, time range, every topic's
// messages, every message's bytes).

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "boicp/io/bag_reader.hpp"
#include "boicp/util/types.hpp"

namespace {

// A small limit, so inputs holding big blobs are refused rather than
// spending the run on copying them.
constexpr uint64_t kFuzzMessageLimit = uint64_t{1} << 20;

void ReadWholeBag(const std::string& path) {
  boicp::BagLimits limits;
  limits.max_message_bytes = kFuzzMessageLimit;
  std::unique_ptr<boicp::BagReader> bag = boicp::OpenBag(path, limits);
  bag->TimeRange();
  for (const boicp::BagTopic& topic : bag->Topics()) {
    for (const boicp::BagMessageRef& ref : bag->Messages(topic.name)) {
      if (bag->Read(ref).size() != ref.size) {
        std::fprintf(stderr, "Read returned another size than Messages declared\n");
        std::abort();
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // One file per process, overwritten by every input.
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("boicp-fuzz-" + std::to_string(::getpid()) + ".db3"))
                               .string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) std::abort();
  }
  try {
    ReadWholeBag(path);
  } catch (const boicp::InputError&) {
    // Malformed input refused with a message: the expected outcome.
  }
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  return 0;
}
