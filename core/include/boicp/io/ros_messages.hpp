#pragma once
// Decoding the ROS messages a drive is logged as, from either serialization
// (ROS 1 or CDR): sensor_msgs/PointCloud2 for scans, nav_msgs/Odometry and
// geometry_msgs/PoseStamped for priors, tf2_msgs/TFMessage for the static
// transform from the odometry's body frame to the sensor's. Every size is checked against the
// message's length before it is read; every failure throws boicp::InputError
// "WHAT: problem", WHAT being the caller's name for the message.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "boicp/io/bag_reader.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// "sensor_msgs/PointCloud2" or "sensor_msgs/msg/PointCloud2".
bool IsPointCloud2Type(const std::string& type);
/// nav_msgs Odometry or geometry_msgs PoseStamped, in either naming style.
bool IsPoseMessageType(const std::string& type);
/// "tf2_msgs/TFMessage" or "tf2_msgs/msg/TFMessage".
bool IsTfMessageType(const std::string& type);

/// What a PointCloud2 declares, read without decoding its points.
struct PointCloud2Info {
  int64_t stamp_ns = 0;  // header.stamp
  std::string frame_id;
  uint64_t points = 0;  // width x height
};

struct DecodedPointCloud2 {
  PointCloud2Info info;
  Points points;                 // the finite x, y, z of every point, metres
  size_t dropped_nonfinite = 0;  // points with a NaN or infinite coordinate
};

/// Reads a PointCloud2's header and size. Throws InputError when the
/// message is truncated or malformed.
PointCloud2Info PeekPointCloud2(const uint8_t* data, size_t size, MessageEncoding encoding,
                                const std::string& what);

/// Decodes a PointCloud2: x, y, z as float32 or float64 at any offset,
/// point_step, row_step, big- or little-endian data. Throws PointLimitError
/// (naming `what`) over `max_points` before allocating, and InputError for a
/// malformed message, missing x/y/z fields, or no finite point.
DecodedPointCloud2 DecodePointCloud2(const uint8_t* data, size_t size, MessageEncoding encoding,
                                     uint64_t max_points, const std::string& what);

struct StampedPose {
  int64_t stamp_ns = 0;  // header.stamp
  std::string frame_id;
  std::string child_frame_id;              // Odometry's body frame; empty for PoseStamped
  Transform pose = Transform::Identity();  // T_frame_child; for Odometry, pose.pose
};

/// Decodes an Odometry or a PoseStamped (`type` as IsPoseMessageType takes
/// it). Throws InputError for a malformed message or a quaternion that is
/// not finite or is far from unit length (|q| outside [0.9, 1.1]).
StampedPose DecodePoseMessage(const uint8_t* data, size_t size, MessageEncoding encoding,
                              const std::string& type, const std::string& what);

/// One transform of a TFMessage: where the child frame is in the parent's.
struct FrameTransform {
  std::string parent;                              // header.frame_id
  std::string child;                               // child_frame_id
  Transform parent_child = Transform::Identity();  // T_parent_child
};

/// Decodes a tf2_msgs/TFMessage (geometry_msgs/TransformStamped[]). Throws
/// InputError as DecodePoseMessage does.
std::vector<FrameTransform> DecodeTfMessage(const uint8_t* data, size_t size,
                                            MessageEncoding encoding, const std::string& what);

}  // namespace boicp
