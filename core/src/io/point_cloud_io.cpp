// Format names and detection, and the LoadPointCloud entry point that runs a
// per-format reader, then drops and counts non-finite points.

#include "boicp/io/point_cloud_io.hpp"

#include <algorithm>
#include <filesystem>

#include "boicp/util/text.hpp"
#include "io/io_readers.hpp"

namespace boicp {

namespace {

constexpr const char* kSupportedExtensions = ".bin .pcd .ply .xyz .txt .png";

Points ReadPoints(const std::string& path, CloudFormat format, const LoadOptions& options) {
  const uint64_t limit = options.max_points;
  switch (format) {
    case CloudFormat::kKittiBin:
      return io_detail::ReadKittiBin(path, limit);
    case CloudFormat::kPcd:
    case CloudFormat::kPly:
      return io_detail::ReadPcdOrPly(path, format, limit);
    case CloudFormat::kXyz:
      return io_detail::ReadXyzText(path, limit);
    case CloudFormat::kDepthPng:
      return io_detail::ReadDepthPng(path, options.depth, limit);
    case CloudFormat::kRosMessage:
      return io_detail::ReadRosMessage(path, options);
    case CloudFormat::kAuto:
      break;
  }
  throw InputError(path + ": no concrete cloud format to read with");
}

// Removes NaN / inf points in place, keeping order; returns how many went.
size_t DropNonFinite(Points* points) {
  const auto end =
      std::remove_if(points->begin(), points->end(), [](const Point& p) { return !p.allFinite(); });
  const auto dropped = static_cast<size_t>(points->end() - end);
  points->erase(end, points->end());
  return dropped;
}

}  // namespace

PointLimitError::PointLimitError(const std::string& path, uint64_t points, uint64_t limit)
    : InputError(path + ": " + std::to_string(points) + " points, over the limit of " +
                 std::to_string(limit)),
      points_(points),
      limit_(limit) {}

namespace io_detail {

void RequirePointCount(const std::string& path, uint64_t points, uint64_t max_points) {
  if (points > max_points) throw PointLimitError(path, points, max_points);
}

}  // namespace io_detail

CloudFormat ParseCloudFormat(const std::string& name) {
  const std::string key = LowerCase(name);
  if (key == "auto") return CloudFormat::kAuto;
  if (key == "kitti" || key == "bin") return CloudFormat::kKittiBin;
  if (key == "pcd") return CloudFormat::kPcd;
  if (key == "ply") return CloudFormat::kPly;
  if (key == "xyz") return CloudFormat::kXyz;
  if (key == "depth" || key == "png") return CloudFormat::kDepthPng;
  throw InputError("unknown cloud format '" + name +
                   "' (expected auto, kitti, bin, pcd, ply, xyz, depth or png)");
}

std::string CloudFormatName(CloudFormat format) {
  switch (format) {
    case CloudFormat::kAuto:
      return "auto";
    case CloudFormat::kKittiBin:
      return "kitti";
    case CloudFormat::kPcd:
      return "pcd";
    case CloudFormat::kPly:
      return "ply";
    case CloudFormat::kXyz:
      return "xyz";
    case CloudFormat::kDepthPng:
      return "depth";
    case CloudFormat::kRosMessage:
      return "ros";
  }
  return "unknown";
}

CloudFormat DetectCloudFormat(const std::string& path) {
  const std::string extension = LowerCase(std::filesystem::path(path).extension().string());
  if (extension == ".bin") return CloudFormat::kKittiBin;
  if (extension == ".pcd") return CloudFormat::kPcd;
  if (extension == ".ply") return CloudFormat::kPly;
  if (extension == ".xyz" || extension == ".txt") return CloudFormat::kXyz;
  if (extension == ".png") return CloudFormat::kDepthPng;
  const std::string found = extension.empty() ? "no extension" : "extension '" + extension + "'";
  throw InputError(path + ": cannot tell the cloud format from " + found +
                   " (supported: " + kSupportedExtensions + "; or give the format explicitly)");
}

LoadedCloud LoadPointCloud(const std::string& path, const LoadOptions& options) {
  // A message's bag may be a folder (a split ROS 2 bag); OpenBag checks it.
  if (options.format != CloudFormat::kRosMessage) io_detail::RequireReadableFile(path);
  LoadedCloud cloud;
  cloud.format = options.format == CloudFormat::kAuto ? DetectCloudFormat(path) : options.format;
  if (options.decode_budget != nullptr) {
    const uint64_t bound = DecodeBoundBytes(path, options);
    try {
      cloud.decode_lease = options.decode_budget->Acquire(bound, options.decode_stop);
    } catch (const LimitExceeded& e) {
      throw LimitExceeded(path + ": " + e.what());
    }
  }
  cloud.points = ReadPoints(path, cloud.format, options);
  const size_t total = cloud.points.size();
  cloud.dropped_nonfinite = DropNonFinite(&cloud.points);
  if (cloud.points.empty()) {
    throw InputError(path + ": no finite points (" + std::to_string(total) + " read, " +
                     std::to_string(cloud.dropped_nonfinite) + " of them NaN/inf)");
  }
  return cloud;
}

}  // namespace boicp
