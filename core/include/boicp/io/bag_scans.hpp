#pragma once
// Which messages of a logged bag are a batch's scans, and the odometry
// recorded beside them as priors.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "boicp/io/ros_messages.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// How the scans are picked from a bag. Times are the recorder's log times.
struct BagScanSelection {
  /// The PointCloud2 topic; empty = the bag's only one.
  std::string topic;
  /// An Odometry or PoseStamped topic: its pose, interpolated at each scan's
  /// header stamp, becomes that scan's prior. Empty = no priors.
  std::string odometry_topic;
  double start = 0.0;         // seconds after the bag's first message, >= 0
  double duration = 0.0;      // seconds kept after start, >= 0; 0 = to the end
  double min_interval = 0.0;  // seconds at least between kept scans, >= 0; 0 = every one
  /// True when any field is set, that is when the path must be a bag.
  bool Any() const;
};

/// The pose at `stamp_ns` from poses sorted by stamp: linear in position,
/// spherical-linear in rotation between the two around it, the pose itself
/// at an equal stamp, nullopt before the first or after the last.
std::optional<Transform> InterpolatePose(const std::vector<StampedPose>& poses, int64_t stamp_ns);

}  // namespace boicp
