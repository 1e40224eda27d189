// libFuzzer harness: arbitrary bytes as a 16-bit depth PNG through
// LoadPointCloud, with 7-Scenes-like intrinsics and scale.

#include "load_fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  boicp::LoadOptions options;
  options.format = boicp::CloudFormat::kDepthPng;
  options.depth.intrinsics = boicp::Intrinsics{585.0, 585.0, 320.0, 240.0};
  options.depth.depth_scale = 1000.0;
  boicp::fuzz::LoadFuzzBytes(data, size, options);
  return 0;
}
