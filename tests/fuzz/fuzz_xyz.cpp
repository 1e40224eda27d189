// libFuzzer harness: arbitrary bytes as a xyz scan through LoadPointCloud.

#include "load_fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  boicp::LoadOptions options;
  options.format = boicp::CloudFormat::kXyz;
  boicp::fuzz::LoadFuzzBytes(data, size, options);
  return 0;
}
