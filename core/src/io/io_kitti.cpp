// KITTI Velodyne scans: rows of little-endian float32 x, y, z, reflectance.

#include <cstdint>
#include <cstring>

#include "io/io_readers.hpp"

namespace boicp::io_detail {

namespace {

constexpr size_t kBytesPerFloat = 4;
constexpr size_t kFloatsPerRow = 4;
constexpr size_t kBytesPerRow = kBytesPerFloat * kFloatsPerRow;

// Assembles the float from its bytes so that the reader is also correct on
// big-endian hosts and never reads through a misaligned float pointer.
float LittleEndianFloat(const unsigned char* bytes) {
  const uint32_t bits = uint32_t{bytes[0]} | uint32_t{bytes[1]} << 8 | uint32_t{bytes[2]} << 16 |
                        uint32_t{bytes[3]} << 24;
  float value = 0.0f;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

}  // namespace

Points ReadKittiBin(const std::string& path, uint64_t max_points) {
  std::ifstream in = OpenOrThrow(path, std::ios::in | std::ios::binary);
  const uint64_t size = FileSizeOrThrow(path);
  if (size == 0) throw InputError(path + ": empty KITTI .bin");
  if (size % kBytesPerRow != 0) {
    throw InputError(path + ": truncated KITTI .bin (" + std::to_string(size) +
                     " bytes is not a multiple of " + std::to_string(kBytesPerRow) + ")");
  }

  RequirePointCount(path, size / kBytesPerRow, max_points);
  const size_t rows = static_cast<size_t>(size / kBytesPerRow);
  std::vector<unsigned char> bytes(static_cast<size_t>(size));
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size))) {
    throw InputError(path + ": read error after " + std::to_string(in.gcount()) + " of " +
                     std::to_string(size) + " bytes");
  }

  Points points;
  points.reserve(rows);
  for (size_t row = 0; row < rows; ++row) {
    const unsigned char* p = bytes.data() + row * kBytesPerRow;
    // The fourth float (reflectance) is not used by registration.
    points.emplace_back(LittleEndianFloat(p), LittleEndianFloat(p + kBytesPerFloat),
                        LittleEndianFloat(p + 2 * kBytesPerFloat));
  }
  return points;
}

}  // namespace boicp::io_detail
