// Depth PNGs and the pinhole intrinsics needed to back-project them.

#include <cmath>
#include <cstring>

#include <open3d/geometry/Image.h>
#include <open3d/io/ImageIO.h>

#include "io/io_readers.hpp"

namespace boicp {

namespace io_detail {

namespace {

constexpr size_t kRawDepthValues = size_t{1} << 16;

// Throws unless the intrinsics can back-project: finite, positive focal
// lengths. `source` names where they came from, for the message.
Intrinsics ValidatedIntrinsics(const std::string& source, double fx, double fy, double cx,
                               double cy) {
  if (!std::isfinite(fx) || !std::isfinite(fy) || !std::isfinite(cx) || !std::isfinite(cy)) {
    throw InputError(source + ": intrinsics must be finite numbers");
  }
  if (fx <= 0.0 || fy <= 0.0) {
    throw InputError(source + ": focal lengths fx and fy must be > 0");
  }
  return Intrinsics{fx, fy, cx, cy};
}

// Maps K = [fx s cx; 0 fy cy; 0 0 1] (row-major) to intrinsics. Skew and a
// non-canonical last row are rejected rather than silently ignored.
Intrinsics IntrinsicsFromMatrix(const std::string& path, const std::vector<double>& k) {
  const bool canonical_rows =
      k[1] == 0.0 && k[3] == 0.0 && k[6] == 0.0 && k[7] == 0.0 && k[8] == 1.0;
  if (!canonical_rows) {
    throw InputError(path + ": camera matrix must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
  }
  return ValidatedIntrinsics(path, k[0], k[4], k[2], k[5]);
}

void RequireDepthOptions(const std::string& path, const DepthOptions& options) {
  if (!options.intrinsics) {
    throw InputError(path +
                     ": a depth PNG needs camera intrinsics (--intrinsics/--intrinsics-file)");
  }
  if (!(options.depth_scale > 0.0) || !std::isfinite(options.depth_scale)) {
    throw InputError(path +
                     ": a depth PNG needs a depth scale > 0 in raw units per metre "
                     "(--depth-scale, e.g. 1000 for 7-Scenes, 5000 for TUM)");
  }
}

uint64_t BigEndianU32(const unsigned char* bytes) {
  return uint64_t{bytes[0]} << 24 | uint64_t{bytes[1]} << 16 | uint64_t{bytes[2]} << 8 |
         uint64_t{bytes[3]};
}

}  // namespace

// Open3D allocates the whole image from the PNG header before decoding it, so
// a 100-byte file declaring 65535 x 65535 pixels costs 8 GB. Deflate expands
// at most 1032-fold, so a header whose pixels cannot come from the file's
// bytes is refused here, as is one over kMaxDepthPixels. Anything that is not
// a PNG header is left to Open3D's own error.
std::optional<PngLayout> RequirePlausiblePngSize(const std::string& path, uint64_t max_points) {
  constexpr uint64_t kDeflateMaxExpansion = 1032;
  constexpr uint64_t kMaxDepthPixels = uint64_t{1} << 26;  // 64 Mpx, 8192 x 8192
  static const unsigned char kSignature[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::ifstream in = OpenOrThrow(path, std::ios::in | std::ios::binary);
  unsigned char head[26] = {};
  if (!in.read(reinterpret_cast<char*>(head), sizeof(head))) return std::nullopt;
  if (std::memcmp(head, kSignature, sizeof(kSignature)) != 0) return std::nullopt;
  if (std::memcmp(head + 12, "IHDR", 4) != 0) return std::nullopt;
  const uint64_t width = BigEndianU32(head + 16);
  const uint64_t height = BigEndianU32(head + 20);
  const uint64_t bit_depth = head[24];
  const uint64_t channels = head[25] == 2 ? 3 : head[25] == 4 ? 2 : head[25] == 6 ? 4 : 1;
  const uint64_t file_size = FileSizeOrThrow(path);
  const std::string size = std::to_string(width) + " x " + std::to_string(height);
  if (width * height > kMaxDepthPixels) {
    throw InputError(path + ": depth PNG of " + size + " pixels is over the 64-megapixel limit");
  }
  if ((width * height * channels * bit_depth + 7) / 8 > kDeflateMaxExpansion * file_size) {
    throw InputError(path + ": corrupt PNG (" + size + " pixels cannot fit in " +
                     std::to_string(file_size) + " bytes)");
  }
  RequirePointCount(path, width * height, max_points);  // a point per pixel at most
  return PngLayout{width, height, channels, bit_depth};
}

namespace {

open3d::geometry::Image ReadSixteenBitGrey(const std::string& path, uint64_t max_points) {
  RequirePlausiblePngSize(path, max_points);
  open3d::geometry::Image image;
  bool ok = false;
  try {
    // The PNG reader proper, so that a depth PNG with an unusual extension
    // still loads when the format is given explicitly.
    ok = open3d::io::ReadImageFromPNG(path, image);
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read PNG (" + e.what() + ")");
  } catch (...) {
    throw InputError(path + ": cannot read PNG (unknown Open3D error)");
  }
  if (!ok) throw InputError(path + ": cannot read PNG (bad header or corrupt data)");
  if (image.num_of_channels_ != 1 || image.bytes_per_channel_ != 2) {
    throw InputError(path + ": depth PNG must be 16-bit single-channel (got " +
                     std::to_string(image.num_of_channels_) + " channels, " +
                     std::to_string(image.bytes_per_channel_) + " bytes per channel)");
  }
  return image;
}

std::vector<bool> InvalidMask(const std::vector<uint16_t>& invalid_values) {
  std::vector<bool> invalid(kRawDepthValues, false);
  for (uint16_t value : invalid_values) invalid[value] = true;
  return invalid;
}

}  // namespace

Points ReadDepthPng(const std::string& path, const DepthOptions& options, uint64_t max_points) {
  RequireDepthOptions(path, options);
  const open3d::geometry::Image image = ReadSixteenBitGrey(path, max_points);
  const Intrinsics& k = *options.intrinsics;
  const std::vector<bool> invalid = InvalidMask(options.invalid_values);

  Points points;
  points.reserve(static_cast<size_t>(image.width_) * static_cast<size_t>(image.height_));
  // Open3D decodes 16-bit PNGs (big-endian on disk) to native-endian uint16
  // rows; memcpy avoids type-punning the byte buffer.
  const uint8_t* data = image.data_.data();
  for (int v = 0; v < image.height_; ++v) {
    for (int u = 0; u < image.width_; ++u) {
      uint16_t raw = 0;
      std::memcpy(&raw, data + (static_cast<size_t>(v) * image.width_ + u) * sizeof(raw),
                  sizeof(raw));
      if (invalid[raw]) continue;
      const double z = raw / options.depth_scale;
      points.emplace_back((u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z);
    }
  }
  return points;
}

}  // namespace io_detail

Intrinsics ParseIntrinsics(const std::string& text) {
  const std::string source = "intrinsics '" + text + "'";
  const std::vector<std::string_view> fields = io_detail::SplitFields(text);
  std::vector<double> values;
  for (std::string_view field : fields) {
    const std::optional<double> value = io_detail::ParseNumber(field);
    if (!value) break;
    values.push_back(*value);
  }
  if (fields.size() != 4 || values.size() != 4) {
    throw InputError(source + ": expected four numbers fx,fy,cx,cy");
  }
  return io_detail::ValidatedIntrinsics(source, values[0], values[1], values[2], values[3]);
}

Intrinsics ReadIntrinsicsFile(const std::string& path) {
  const std::vector<double> numbers = io_detail::ReadNumbersFile(path);
  if (numbers.size() == 4) {
    return io_detail::ValidatedIntrinsics(path, numbers[0], numbers[1], numbers[2], numbers[3]);
  }
  if (numbers.size() == 9) return io_detail::IntrinsicsFromMatrix(path, numbers);
  throw InputError(path + ": expected 4 numbers (fx fy cx cy) or 9 (3x3 camera matrix), got " +
                   std::to_string(numbers.size()));
}

}  // namespace boicp
