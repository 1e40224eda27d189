#include "boicp/icp/voxel_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <vector>

namespace boicp {
namespace {

void AppendLittleEndian(float value, std::vector<char>& out) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int shift = 0; shift < 32; shift += 8)
    out.push_back(static_cast<char>((bits >> shift) & 0xff));
}

}  // namespace

size_t VoxelAccumulator::KeyHash::operator()(const Key& k) const {
  // Large odd multipliers spread neighbouring voxels over the table.
  const uint64_t h = static_cast<uint64_t>(k[0]) * 73856093ULL ^
                     static_cast<uint64_t>(k[1]) * 19349663ULL ^
                     static_cast<uint64_t>(k[2]) * 83492791ULL;
  return static_cast<size_t>(h);
}

VoxelAccumulator::VoxelAccumulator(double voxel) : voxel_(voxel) {
  if (!(voxel > 0.0) || !std::isfinite(voxel)) {
    throw InputError("voxel size must be a positive number of metres");
  }
}

void VoxelAccumulator::Add(const Points& points, const Transform& T) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  // Beyond 2^62 voxels from the origin an index no longer fits the key (its
  // cast would be undefined): such a point is left out, as a non-finite one is.
  constexpr double kMaxIndex = 4.6e18;
  for (const Point& p : points) {
    const Point q = R * p + t;
    const Eigen::Vector3d index = (q / voxel_).array().floor();
    if (!index.allFinite() || index.cwiseAbs().maxCoeff() > kMaxIndex) continue;
    const Key key{static_cast<int64_t>(index.x()), static_cast<int64_t>(index.y()),
                  static_cast<int64_t>(index.z())};
    Cell& cell = cells_[key];
    cell.sum += q;
    ++cell.count;
  }
}

Points VoxelAccumulator::Centroids() const {
  std::vector<std::pair<Key, const Cell*>> ordered;
  ordered.reserve(cells_.size());
  for (const auto& [key, cell] : cells_) ordered.emplace_back(key, &cell);
  std::sort(ordered.begin(), ordered.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  Points out;
  out.reserve(ordered.size());
  for (const auto& [key, cell] : ordered) {
    out.emplace_back(cell->sum / static_cast<double>(cell->count));
  }
  return out;
}

void WritePlyPoints(const std::string& path, const Points& points) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out << "ply\nformat binary_little_endian 1.0\ncomment boicp merged map, metres\n"
      << "element vertex " << points.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\nend_header\n";
  std::vector<char> buffer;
  buffer.reserve(points.size() * 12);
  for (const Point& p : points) {
    AppendLittleEndian(static_cast<float>(p.x()), buffer);
    AppendLittleEndian(static_cast<float>(p.y()), buffer);
    AppendLittleEndian(static_cast<float>(p.z()), buffer);
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  if (!out.flush()) throw std::runtime_error(path + ": write failed");
}

}  // namespace boicp
