#pragma once
// Test-only encoders for the ROS messages boicp decodes, in either
// serialization (ROS 1 or CDR), with knobs for the layouts real drivers write
// and for the lies a malformed message tells.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "boicp/io/bag_reader.hpp"
#include "boicp/io/ros_messages.hpp"
#include "boicp/util/types.hpp"

namespace boicp::test {

/// How EncodePointCloud2 lays its points out, and what it may lie about.
struct PointCloud2Options {
  bool float64 = false;        // x, y, z as FLOAT64 (else FLOAT32)
  bool big_endian = false;     // the point data (is_bigendian), and for CDR the message too
  bool intensity = false;      // a FLOAT32 "intensity" field before x, so x is not at offset 0
  uint32_t point_padding = 0;  // unused bytes after the fields (point_step grows)
  uint32_t nan_points = 0;     // NaN points appended after `points`
  uint32_t height = 1;         // rows; the point count (with NaNs) must divide by it
  uint32_t row_padding = 0;    // unused bytes after each row (row_step grows)
  // Lies, for malformed messages: each replaces what the encoder would write.
  std::optional<uint32_t> width;
  std::optional<uint32_t> point_step;
  std::optional<uint32_t> row_step;
  std::optional<uint32_t> x_offset;
  std::optional<uint8_t> x_datatype;
  bool omit_z = false;
};

/// A sensor_msgs/PointCloud2 holding `points` (then options.nan_points NaN
/// points). Throws std::invalid_argument when height does not divide them.
std::vector<uint8_t> EncodePointCloud2(const Points& points, int64_t stamp_ns,
                                       const std::string& frame_id, MessageEncoding encoding,
                                       const PointCloud2Options& options = {});

/// A nav_msgs/Odometry with pose.pose = `pose` (its rotation as a quaternion,
/// or `quaternion_xyzw` verbatim when given) and zero covariances and twist.
std::vector<uint8_t> EncodeOdometry(const Transform& pose, int64_t stamp_ns,
                                    const std::string& frame_id, MessageEncoding encoding,
                                    const std::optional<Eigen::Vector4d>& quaternion_xyzw = {});

/// A geometry_msgs/PoseStamped, as EncodeOdometry.
std::vector<uint8_t> EncodePoseStamped(const Transform& pose, int64_t stamp_ns,
                                       const std::string& frame_id, MessageEncoding encoding,
                                       const std::optional<Eigen::Vector4d>& quaternion_xyzw = {});

/// A tf2_msgs/TFMessage holding one TransformStamped per entry of
/// `transforms`.
std::vector<uint8_t> EncodeTfMessage(const std::vector<FrameTransform>& transforms,
                                     int64_t stamp_ns, MessageEncoding encoding);

}  // namespace boicp::test
