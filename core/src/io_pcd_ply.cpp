// PCD and PLY through Open3D's readers.
//
// Open3D reports most failures by printing a warning and returning false, but
// its LogError throws std::runtime_error, and a failed PLY read can leave
// garbage points behind. So the return value is authoritative, everything
// thrown is converted to InputError, and a PLY's magic line is checked first
// to name the most common mistake precisely. Open3D's (and RPly's) console
// warnings are let through: silencing them would mean changing global state.

#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include "io_readers.hpp"

namespace boicp::io_detail {

namespace {

void RequirePlyMagic(const std::string& path) {
  std::ifstream in = OpenOrThrow(path, std::ios::in | std::ios::binary);
  std::string first_line;
  std::getline(in, first_line);
  if (!first_line.empty() && first_line.back() == '\r') first_line.pop_back();
  if (first_line != "ply") {
    throw InputError(path + ": bad PLY header (first line is not 'ply')");
  }
}

}  // namespace

Points ReadPcdOrPly(const std::string& path, CloudFormat format) {
  const bool is_ply = format == CloudFormat::kPly;
  const std::string name = is_ply ? "PLY" : "PCD";
  if (is_ply) RequirePlyMagic(path);

  open3d::io::ReadPointCloudOption option;
  option.format = is_ply ? "ply" : "pcd";
  // Keep NaN / inf points so that LoadPointCloud can count what it drops.
  option.remove_nan_points = false;
  option.remove_infinite_points = false;
  option.print_progress = false;

  open3d::geometry::PointCloud cloud;
  bool ok = false;
  try {
    ok = open3d::io::ReadPointCloud(path, cloud, option);
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read " + name + " (" + e.what() + ")");
  } catch (...) {
    throw InputError(path + ": cannot read " + name + " (unknown Open3D error)");
  }
  if (!ok) {
    throw InputError(path + ": cannot read " + name +
                     " (bad header, no x/y/z vertices, or truncated data)");
  }
  return std::move(cloud.points_);
}

}  // namespace boicp::io_detail
