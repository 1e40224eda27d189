// A depth PNG's declared size is checked before Open3D allocates the image:
// a 60-byte file declaring 65535 x 65535 pixels used to cost 8 GB.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string BigEndianU32(uint32_t value) {
  std::string bytes;
  for (int shift = 24; shift >= 0; shift -= 8) bytes.push_back(static_cast<char>(value >> shift));
  return bytes;
}

// Signature and IHDR of a 16-bit greyscale PNG, then `padding` zero bytes
// (the CRC is not checked before the size is).
std::string PngHeader(uint32_t width, uint32_t height, size_t padding) {
  return std::string("\x89PNG\r\n\x1a\n", 8) + BigEndianU32(13) + "IHDR" + BigEndianU32(width) +
         BigEndianU32(height) + std::string("\x10\x00\x00\x00\x00", 5) + std::string(padding, '\0');
}

std::string LoadError(const std::string& bytes) {
  const fs::path path =
      fs::path(::testing::TempDir()) / ("boicp_png_" + std::to_string(std::random_device()()));
  std::ofstream(path, std::ios::binary) << bytes;
  LoadOptions options;
  options.format = CloudFormat::kDepthPng;
  options.depth.intrinsics = Intrinsics{500, 500, 320, 240};
  options.depth.depth_scale = 1000;
  std::string message;
  try {
    LoadPointCloud(path.string(), options);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    message = e.what();
    EXPECT_THAT(message, HasSubstr(path.string()));
  }
  fs::remove(path);
  return message;
}

TEST(DepthPngHeaderTest, PixelsTheFileCannotHoldAreRefusedBeforeDecoding) {
  EXPECT_THAT(LoadError(PngHeader(4000, 4000, 40)), HasSubstr("4000 x 4000 pixels cannot fit"));
}

TEST(DepthPngHeaderTest, ImagesOverTheMegapixelLimitAreRefused) {
  EXPECT_THAT(LoadError(PngHeader(65535, 65535, 40)), HasSubstr("over the 64-megapixel limit"));
}

TEST(DepthPngHeaderTest, ASmallCorruptPngStillGetsTheDecoderError) {
  EXPECT_THAT(LoadError(PngHeader(4, 3, 40)), HasSubstr("cannot read PNG"));
}

}  // namespace
}  // namespace boicp
