#pragma once
// The transform between two frames of a tf tree (a bag's /tf_static), used
// to carry odometry of a vehicle's body frame to the sensor that took the
// scans.

#include <optional>
#include <string>
#include <vector>

#include "boicp/io/ros_messages.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// T_from_to: where frame `to` is in frame `from`, composed through the
/// parents `transforms` give (each T_parent_child; a later one for the same
/// child replaces an earlier one). Frame names compare without a leading
/// '/', as tf does. Identity when the frames are the same; nullopt when
/// either is missing from the tree or the two are in different trees.
/// Throws InputError when following parents runs in a cycle.
std::optional<Transform> TransformBetween(const std::vector<FrameTransform>& transforms,
                                          const std::string& from, const std::string& to);

}  // namespace boicp
