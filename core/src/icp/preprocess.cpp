#include "boicp/icp/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include <open3d/utility/Helper.h>

namespace boicp {

Points CropByRange(PointSpan points, double min_range, double max_range) {
  const double min_sq = min_range * min_range;
  const double max_sq = max_range > 0.0 ? max_range * max_range : -1.0;
  Points kept;
  kept.reserve(points.size());
  for (const Point& p : points) {
    const double r_sq = p.squaredNorm();
    if (r_sq < min_sq) continue;
    if (max_sq >= 0.0 && r_sq > max_sq) continue;
    kept.push_back(p);
  }
  return kept;
}

namespace {

// Cell keys to cell numbers, by open addressing with linear probing: one
// flat array instead of a node per cell, which is what makes a fine grid of a
// large scan cheap. The table is at most half full.
class CellNumbers {
 public:
  using Key = Eigen::Vector3i;

  // The number of `key`'s cell; a new cell gets the next number.
  int32_t NumberOf(const Key& key) {
    Slot* slot = &Find(key);
    if (slot->number < 0) {
      if (2 * (cells_ + 1) > slots_.size()) {
        Grow();
        slot = &Find(key);
      }
      *slot = {key, static_cast<int32_t>(cells_++)};
    }
    return slot->number;
  }

 private:
  struct Slot {
    Key key = Key::Zero();
    int32_t number = -1;  // -1: empty
  };

  Slot& Find(const Key& key) {
    const size_t mask = slots_.size() - 1;
    size_t i = Hash(key) & mask;
    while (slots_[i].number >= 0 && slots_[i].key != key) i = (i + 1) & mask;
    return slots_[i];
  }

  static size_t Hash(const Key& key) {
    uint64_t h = static_cast<uint64_t>(static_cast<uint32_t>(key.x())) * 0x9E3779B97F4A7C15ULL ^
                 static_cast<uint64_t>(static_cast<uint32_t>(key.y())) * 0xC2B2AE3D27D4EB4FULL ^
                 static_cast<uint64_t>(static_cast<uint32_t>(key.z())) * 0x165667B19E3779F9ULL;
    return static_cast<size_t>(h ^ (h >> 29));
  }

  void Grow() {
    std::vector<Slot> old(2 * slots_.size());
    old.swap(slots_);
    for (const Slot& slot : old) {
      if (slot.number >= 0) Find(slot.key) = slot;
    }
  }

  std::vector<Slot> slots_ = std::vector<Slot>(1024);
  size_t cells_ = 0;
};

}  // namespace

// Open3D's voxel grid (PointCloud::VoxelDownSample): the same origin and
// cell keys, and each cell's points summed in the cloud's order, so every
// centroid is Open3D's bit for bit.
Points VoxelDownsample(const Points& points, double voxel, CellOrder order) {
  if (voxel <= 0.0 || points.empty()) return points;
  Point lowest = points.front(), highest = points.front();
  for (const Point& p : points) {
    lowest = lowest.cwiseMin(p);
    highest = highest.cwiseMax(p);
  }
  // Cell keys are ints.
  if ((highest - lowest).maxCoeff() / voxel + 1.0 >= std::numeric_limits<int>::max()) {
    throw InputError("voxel " + std::to_string(voxel) + " m is too small for a cloud " +
                     std::to_string((highest - lowest).maxCoeff()) + " m across");
  }
  const Point origin = lowest - Point::Constant(voxel) * 0.5;
  struct Cell {
    Eigen::Vector3i key;
    Point sum = Point::Zero();
    int count = 0;
  };
  CellNumbers numbers;
  std::vector<Cell> cells;  // in the order the cloud first reaches them
  // Scans list neighbouring points one after another, so a point often
  // falls in the previous point's cell, which needs no lookup.
  Cell* previous = nullptr;
  for (const Point& p : points) {
    const Point scaled = (p - origin) / voxel;
    const Eigen::Vector3i key(static_cast<int>(std::floor(scaled.x())),
                              static_cast<int>(std::floor(scaled.y())),
                              static_cast<int>(std::floor(scaled.z())));
    if (previous == nullptr || key != previous->key) {
      const auto number = static_cast<size_t>(numbers.NumberOf(key));
      if (number == cells.size()) cells.push_back({key});
      previous = &cells[number];
    }
    previous->sum += p;
    ++previous->count;
  }
  const auto centroid = [](const Cell& cell) -> Point {
    return cell.sum / static_cast<double>(cell.count);
  };
  Points centroids;
  centroids.reserve(cells.size());
  if (order == CellOrder::kFirstReached) {
    for (const Cell& cell : cells) centroids.push_back(centroid(cell));
    return centroids;
  }
  // Open3D inserts each key into this map when the cloud first reaches its
  // cell; the same insertions give the same iteration order.
  std::unordered_map<Eigen::Vector3i, size_t, open3d::utility::hash_eigen<Eigen::Vector3i>> map;
  for (size_t number = 0; number < cells.size(); ++number) map.emplace(cells[number].key, number);
  for (const auto& [key, number] : map) centroids.push_back(centroid(cells[number]));
  return centroids;
}

Points RandomSubsample(PointSpan points, size_t max_points, uint64_t seed) {
  if (max_points == 0 || max_points >= points.size()) return points.ToPoints();
  std::vector<size_t> indices(points.size());
  std::iota(indices.begin(), indices.end(), size_t{0});
  std::mt19937_64 rng(seed);
  // Partial Fisher-Yates: the first max_points entries become a uniform sample.
  for (size_t i = 0; i < max_points; ++i) {
    std::uniform_int_distribution<size_t> pick(i, indices.size() - 1);
    std::swap(indices[i], indices[pick(rng)]);
  }
  indices.resize(max_points);
  std::sort(indices.begin(), indices.end());
  Points sample;
  sample.reserve(max_points);
  for (size_t i : indices) sample.push_back(points[i]);
  return sample;
}

Point Centroid(const Points& points) {
  Point sum = Point::Zero();
  for (const Point& p : points) sum += p;
  return points.empty() ? sum : Point(sum / static_cast<double>(points.size()));
}

double RmsRadius(const Points& points) {
  if (points.empty()) return 0.0;
  const Point centre = Centroid(points);
  Eigen::Vector3d squares = Eigen::Vector3d::Zero();
  for (const Point& p : points) squares += (p - centre).cwiseAbs2();
  squares /= static_cast<double>(points.size());
  return std::sqrt(squares.sum());
}

}  // namespace boicp
