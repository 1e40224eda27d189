// libFuzzer harness: arbitrary bytes as a ROS 2 .mcap file, read whole
// through OpenBag (ReadFuzzBag).

#include "load_fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  boicp::fuzz::ReadFuzzBag(data, size, ".mcap");
  return 0;
}
