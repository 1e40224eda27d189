#pragma once
// A merged point cloud of many scans kept at one point per voxel (the
// centroid), so memory grows with the mapped volume, not with the number of
// scans; and a PLY writer for it.

#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>

#include "boicp/util/types.hpp"

namespace boicp {

class VoxelAccumulator {
 public:
  /// Precondition: voxel > 0 (metres). Throws InputError otherwise.
  explicit VoxelAccumulator(double voxel);

  /// Adds T * p for every p of `points`; a point that is not finite, or lies
  /// more than 2^62 voxels from the origin, is left out.
  void Add(const Points& points, const Transform& T = Transform::Identity());

  /// One centroid per occupied voxel, ordered by voxel index so that the
  /// output does not depend on hash-table order.
  Points Centroids() const;

  size_t size() const { return cells_.size(); }

 private:
  using Key = std::array<int64_t, 3>;
  struct KeyHash {
    size_t operator()(const Key& k) const;
  };
  struct Cell {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int64_t count = 0;
  };
  double voxel_;
  std::unordered_map<Key, Cell, KeyHash> cells_;
};

/// Writes a binary little-endian PLY with float x, y, z vertices. Throws
/// std::runtime_error when the file cannot be written.
void WritePlyPoints(const std::string& path, const Points& points);

}  // namespace boicp
