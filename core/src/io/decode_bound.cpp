// An upper bound on what decoding a scan allocates, from its header alone.
//
// Each format's header is checked by the same function its reader runs
// first, so a file the bound accepts is one the reader starts on, and the
// bound counts what that reader then allocates: Open3D's decoding buffers,
// the Eigen::Vector3d arrays (points, and normals or colours when the file
// names them) it sizes by the declared count, and our own copies.

#include "io/io_readers.hpp"

namespace boicp {

namespace {

constexpr uint64_t kVectorBytes = sizeof(Point);  // an Eigen::Vector3d: 24 bytes
// One text line in flight: Open3D's 1 KiB line buffer and the fields split
// from it (the PCD check refuses longer lines).
constexpr uint64_t kTextLineBytes = 4096;

// Open3D's point cloud: points, and normals and colours when present.
uint64_t CloudArrays(uint64_t points, bool normals, bool colors) {
  return points * kVectorBytes * (1 + (normals ? 1 : 0) + (colors ? 1 : 0));
}

uint64_t PcdBound(const std::string& path, uint64_t max_points) {
  const io_detail::PcdLayout pcd = io_detail::ReadPcdLayout(path, max_points);
  // Open3D reads binary data a point at a time, but inflates binary_compressed
  // data whole next to its compressed copy; ascii lines are read one by one.
  const uint64_t buffers = pcd.compressed ? pcd.compressed_bytes + pcd.points * pcd.point_bytes
                           : pcd.ascii    ? kTextLineBytes
                                          : pcd.point_bytes;
  return buffers + CloudArrays(pcd.points, pcd.normals, pcd.colors);
}

uint64_t PlyBound(const std::string& path, uint64_t max_points) {
  const io_detail::PlyLayout ply = io_detail::RequirePlyHeaderFits(path, max_points);
  return CloudArrays(ply.vertices, ply.normals, ply.colors);
}

uint64_t KittiBound(const std::string& path, uint64_t max_points) {
  // ReadKittiBin reads the whole file, then keeps x/y/z of each 16-byte row.
  const uint64_t size = io_detail::FileSizeOrThrow(path);
  const uint64_t rows = size / 16;
  io_detail::RequirePointCount(path, rows, max_points);
  return size + rows * kVectorBytes;
}

uint64_t XyzBound(const std::string& path, uint64_t max_points) {
  // Text declares no count: counting lines streams the file in small reads.
  const uint64_t lines = io_detail::CountDataLines(path);
  io_detail::RequirePointCount(path, lines, max_points);
  return kTextLineBytes + lines * kVectorBytes;
}

uint64_t DepthPngBound(const std::string& path, uint64_t max_points) {
  const std::optional<io_detail::PngLayout> png =
      io_detail::RequirePlausiblePngSize(path, max_points);
  // Not a PNG: Open3D refuses it before it allocates pixels.
  if (!png) return io_detail::FileSizeOrThrow(path);
  const uint64_t pixels = png->width * png->height;
  const uint64_t image = (pixels * png->channels * png->bit_depth + 7) / 8;
  // The decoded image, and a point per pixel at most.
  return image + pixels * kVectorBytes;
}

}  // namespace

uint64_t DecodeBoundBytes(const std::string& path, const LoadOptions& options) {
  if (options.format != CloudFormat::kRosMessage) io_detail::RequireReadableFile(path);
  const CloudFormat format =
      options.format == CloudFormat::kAuto ? DetectCloudFormat(path) : options.format;
  const uint64_t limit = options.max_points;
  switch (format) {
    case CloudFormat::kKittiBin:
      return KittiBound(path, limit);
    case CloudFormat::kPcd:
      return PcdBound(path, limit);
    case CloudFormat::kPly:
      return PlyBound(path, limit);
    case CloudFormat::kXyz:
      return XyzBound(path, limit);
    case CloudFormat::kDepthPng:
      return DepthPngBound(path, limit);
    case CloudFormat::kRosMessage:
      return io_detail::RosMessageBound(path, options);
    case CloudFormat::kAuto:
      break;
  }
  throw InputError(path + ": no concrete cloud format to bound");
}

}  // namespace boicp
