#include "boicp/mapping/occupancy_map.hpp"

#include <cmath>
#include <fstream>

#include <octomap/OcTree.h>

namespace boicp {
namespace {

void Require(bool ok, const std::string& message) {
  if (!ok) throw InputError("map settings: " + message);
}

}  // namespace

struct OccupancyMap::Impl {
  explicit Impl(const OccupancySettings& s) : settings(s), tree(s.resolution) {
    tree.setProbHit(s.prob_hit);
    tree.setProbMiss(s.prob_miss);
    tree.setClampingThresMin(s.clamp_min);
    tree.setClampingThresMax(s.clamp_max);
  }
  OccupancySettings settings;
  octomap::OcTree tree;
  bool inner_dirty = false;  // lazy insertion leaves inner nodes stale until updated

  void UpdateInner() {
    if (!inner_dirty) return;
    tree.updateInnerOccupancy();
    inner_dirty = false;
  }
};

void ValidateOccupancySettings(const OccupancySettings& s) {
  Require(std::isfinite(s.resolution) && s.resolution >= 0.001 && s.resolution <= 100.0,
          "resolution must be between 0.001 and 100 m");
  Require(std::isfinite(s.max_range) && s.max_range >= 0.0,
          "max_range must be >= 0 (0 = no limit)");
  Require(s.prob_hit > 0.5 && s.prob_hit < 1.0, "prob_hit must be in (0.5, 1)");
  Require(s.prob_miss > 0.0 && s.prob_miss < 0.5, "prob_miss must be in (0, 0.5)");
  Require(s.clamp_min > 0.0 && s.clamp_min < s.clamp_max && s.clamp_max < 1.0,
          "clamping thresholds must satisfy 0 < clamp_min < clamp_max < 1");
}

OccupancyMap::OccupancyMap(const OccupancySettings& settings) {
  ValidateOccupancySettings(settings);
  impl_ = std::make_unique<Impl>(settings);
}

OccupancyMap::~OccupancyMap() = default;

void OccupancyMap::InsertScan(const Points& points, const Transform& T_map_scan,
                              const Point& sensor_origin) {
  const Eigen::Matrix3d R = T_map_scan.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_map_scan.topRightCorner<3, 1>();
  octomap::Pointcloud cloud;
  cloud.reserve(points.size());
  for (const Point& p : points) {
    const Point q = R * p + t;
    cloud.push_back(static_cast<float>(q.x()), static_cast<float>(q.y()),
                    static_cast<float>(q.z()));
  }
  const Point origin = R * sensor_origin + t;
  const double max_range = impl_->settings.max_range > 0.0 ? impl_->settings.max_range : -1.0;
  impl_->tree.insertPointCloud(
      cloud,
      octomap::point3d(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                       static_cast<float>(origin.z())),
      max_range, /*lazy_eval=*/true, /*discretize=*/true);
  impl_->inner_dirty = true;
}

size_t OccupancyMap::OccupiedLeaves() {
  impl_->UpdateInner();
  size_t count = 0;
  for (auto it = impl_->tree.begin_leafs(), end = impl_->tree.end_leafs(); it != end; ++it) {
    if (impl_->tree.isNodeOccupied(*it)) ++count;
  }
  return count;
}

// The stream overloads, because OctoMap's file-name overloads print progress
// to stdout, which is the daemon's log.
void OccupancyMap::WriteFull(const std::string& path) {
  impl_->UpdateInner();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out || !impl_->tree.write(out) || !out.flush()) {
    throw std::runtime_error(path + ": cannot write OctoMap .ot");
  }
}

void OccupancyMap::WriteBinary(const std::string& path) {
  impl_->UpdateInner();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out || !impl_->tree.writeBinary(out) || !out.flush()) {
    throw std::runtime_error(path + ": cannot write OctoMap .bt");
  }
}

}  // namespace boicp
