#include "boicp/io/ros_messages.hpp"

#include <cmath>
#include <cstring>

#include "boicp/io/point_cloud_io.hpp"
#include "message_cursor.hpp"

namespace boicp {
namespace {

using io_detail::MessageCursor;

constexpr uint8_t kFloat32 = 7;
constexpr uint8_t kFloat64 = 8;

bool IsOneOf(const std::string& type, const char* ros1, const char* ros2) {
  return type == ros1 || type == ros2;
}

bool IsOdometryType(const std::string& type) {
  return IsOneOf(type, "nav_msgs/Odometry", "nav_msgs/msg/Odometry");
}

bool IsPoseStampedType(const std::string& type) {
  return IsOneOf(type, "geometry_msgs/PoseStamped", "geometry_msgs/msg/PoseStamped");
}

// std_msgs/Header: ROS 1 has a seq before the stamp, ROS 2 does not.
void ReadHeader(MessageCursor& cursor, int64_t& stamp_ns, std::string& frame_id) {
  int64_t sec = 0;
  if (cursor.encoding() == MessageEncoding::kRos1) {
    cursor.U32("header.seq");
    sec = cursor.U32("header.stamp.sec");
  } else {
    sec = cursor.I32("header.stamp.sec");
  }
  const uint32_t nsec = cursor.U32("header.stamp.nsec");
  // |sec| < 2^32 and nsec < 2^32, so this cannot overflow an int64.
  stamp_ns = sec * 1000000000 + int64_t{nsec};
  frame_id = cursor.String("header.frame_id");
}

// Where one coordinate sits inside a point.
struct CoordinateField {
  bool found = false;
  uint32_t offset = 0;
  uint8_t datatype = 0;
};

// Everything a PointCloud2 declares, with its data in place.
struct CloudLayout {
  PointCloud2Info info;
  uint32_t height = 0;
  uint32_t width = 0;
  CoordinateField xyz[3];
  bool big_endian = false;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  const uint8_t* data = nullptr;
  size_t data_size = 0;
};

// A PointField's smallest serialized size: empty name (4), offset (4),
// datatype (1), count (4). Bounds the field loop by the message length.
constexpr size_t kMinPointFieldBytes = 13;

void ReadPointField(MessageCursor& cursor, CloudLayout& layout) {
  const std::string name = cursor.String("fields.name");
  const uint32_t offset = cursor.U32("fields.offset");
  const uint8_t datatype = cursor.U8("fields.datatype");
  cursor.U32("fields.count");
  const int axis = name == "x" ? 0 : name == "y" ? 1 : name == "z" ? 2 : -1;
  // The first field of a name wins, as in PCL.
  if (axis < 0 || layout.xyz[axis].found) return;
  layout.xyz[axis] = {true, offset, datatype};
}

CloudLayout ReadCloudLayout(MessageCursor& cursor) {
  CloudLayout layout;
  ReadHeader(cursor, layout.info.stamp_ns, layout.info.frame_id);
  layout.height = cursor.U32("height");
  layout.width = cursor.U32("width");
  layout.info.points = uint64_t{layout.height} * layout.width;
  const uint32_t fields = cursor.Count(kMinPointFieldBytes, "fields");
  for (uint32_t i = 0; i < fields; ++i) ReadPointField(cursor, layout);
  layout.big_endian = cursor.U8("is_bigendian") != 0;
  layout.point_step = cursor.U32("point_step");
  layout.row_step = cursor.U32("row_step");
  layout.data_size = cursor.Count(1, "data");
  layout.data = cursor.Bytes(layout.data_size, "data");
  cursor.U8("is_dense");
  return layout;
}

size_t DatatypeBytes(uint8_t datatype) {
  return datatype == kFloat32 ? 4 : datatype == kFloat64 ? 8 : 0;
}

void CheckCoordinateFields(const MessageCursor& cursor, const CloudLayout& layout) {
  static const char* const kNames[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const CoordinateField& field = layout.xyz[axis];
    const std::string name = kNames[axis];
    if (!field.found) cursor.Fail("no '" + name + "' field (needs x, y and z)");
    const size_t bytes = DatatypeBytes(field.datatype);
    if (bytes == 0) {
      cursor.Fail("field '" + name + "' has datatype " + std::to_string(field.datatype) +
                  "; x, y and z must be FLOAT32 (7) or FLOAT64 (8)");
    }
    if (uint64_t{field.offset} + bytes > layout.point_step) {
      cursor.Fail("field '" + name + "' at offset " + std::to_string(field.offset) +
                  " does not fit in point_step " + std::to_string(layout.point_step));
    }
  }
}

// Every point must lie inside the data: rows of row_step bytes, each holding
// width points of point_step bytes. All products fit in 64 bits (u32 x u32).
void CheckCloudGeometry(const MessageCursor& cursor, const CloudLayout& layout) {
  if (layout.info.points == 0) cursor.Fail("the cloud has no points (width x height is 0)");
  CheckCoordinateFields(cursor, layout);
  const uint64_t row_bytes = uint64_t{layout.width} * layout.point_step;
  if (layout.height > 1 && layout.row_step < row_bytes) {
    cursor.Fail("row_step " + std::to_string(layout.row_step) +
                " is less than width x point_step " + std::to_string(row_bytes));
  }
  const uint64_t needed = uint64_t{layout.height - 1} * layout.row_step + row_bytes;
  if (needed > layout.data_size) {
    cursor.Fail(std::to_string(layout.width) + " x " + std::to_string(layout.height) +
                " points need " + std::to_string(needed) + " data bytes but the message has " +
                std::to_string(layout.data_size));
  }
}

double ReadCoordinate(const uint8_t* at, uint8_t datatype, bool big_endian) {
  const size_t width = DatatypeBytes(datatype);
  uint64_t bits = 0;
  for (size_t i = 0; i < width; ++i) {
    const size_t shift = big_endian ? (width - 1 - i) : i;
    bits |= uint64_t{at[i]} << (8 * shift);
  }
  if (datatype == kFloat32) {
    const uint32_t narrow = static_cast<uint32_t>(bits);
    float value;
    std::memcpy(&value, &narrow, sizeof value);
    return value;
  }
  double value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

void DecodePoints(const CloudLayout& layout, DecodedPointCloud2& cloud) {
  cloud.points.reserve(layout.info.points);
  for (uint32_t row = 0; row < layout.height; ++row) {
    const uint8_t* row_start = layout.data + size_t{row} * layout.row_step;
    for (uint32_t column = 0; column < layout.width; ++column) {
      const uint8_t* point = row_start + size_t{column} * layout.point_step;
      Point p;
      for (int axis = 0; axis < 3; ++axis) {
        const CoordinateField& field = layout.xyz[axis];
        p[axis] = ReadCoordinate(point + field.offset, field.datatype, layout.big_endian);
      }
      if (p.allFinite()) {
        cloud.points.push_back(p);
      } else {
        ++cloud.dropped_nonfinite;
      }
    }
  }
}

// geometry_msgs/Pose: position, then orientation x, y, z, w. A
// geometry_msgs/Transform (translation, rotation) has the same layout.
Transform ReadPose(MessageCursor& cursor) {
  Eigen::Vector3d t;
  t.x() = cursor.F64("pose.position.x");
  t.y() = cursor.F64("pose.position.y");
  t.z() = cursor.F64("pose.position.z");
  Eigen::Vector4d q;  // x, y, z, w
  for (int i = 0; i < 4; ++i) q[i] = cursor.F64("pose.orientation");
  if (!t.allFinite()) cursor.Fail("pose position is not finite");
  if (!q.allFinite()) cursor.Fail("pose orientation is not finite");
  const double norm = q.norm();
  if (norm < 0.9 || norm > 1.1) {
    cursor.Fail("pose orientation is not a unit quaternion (norm " + std::to_string(norm) + ")");
  }
  q /= norm;
  Transform pose = Transform::Identity();
  pose.topLeftCorner<3, 3>() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).toRotationMatrix();
  pose.topRightCorner<3, 1>() = t;
  return pose;
}

// nav_msgs/Odometry: header, child_frame_id, pose (pose, covariance[36]),
// twist (linear, angular, covariance[36]). The twist is read only so a
// truncated message is refused.
StampedPose ReadOdometry(MessageCursor& cursor) {
  StampedPose result;
  ReadHeader(cursor, result.stamp_ns, result.frame_id);
  result.child_frame_id = cursor.String("child_frame_id");
  result.pose = ReadPose(cursor);
  cursor.SkipPrimitives(36, 8, "pose.covariance");
  cursor.SkipPrimitives(6, 8, "twist.twist");
  cursor.SkipPrimitives(36, 8, "twist.covariance");
  return result;
}

StampedPose ReadPoseStamped(MessageCursor& cursor) {
  StampedPose result;
  ReadHeader(cursor, result.stamp_ns, result.frame_id);
  result.pose = ReadPose(cursor);
  return result;
}

}  // namespace

bool IsPointCloud2Type(const std::string& type) {
  return IsOneOf(type, "sensor_msgs/PointCloud2", "sensor_msgs/msg/PointCloud2");
}

bool IsPoseMessageType(const std::string& type) {
  return IsOdometryType(type) || IsPoseStampedType(type);
}

bool IsTfMessageType(const std::string& type) {
  return IsOneOf(type, "tf2_msgs/TFMessage", "tf2_msgs/msg/TFMessage");
}

PointCloud2Info PeekPointCloud2(const uint8_t* data, size_t size, MessageEncoding encoding,
                                const std::string& what) {
  MessageCursor cursor(data, size, encoding, what);
  return ReadCloudLayout(cursor).info;
}

DecodedPointCloud2 DecodePointCloud2(const uint8_t* data, size_t size, MessageEncoding encoding,
                                     uint64_t max_points, const std::string& what) {
  MessageCursor cursor(data, size, encoding, what);
  const CloudLayout layout = ReadCloudLayout(cursor);
  if (layout.info.points > max_points) {
    throw PointLimitError(what, layout.info.points, max_points);
  }
  CheckCloudGeometry(cursor, layout);
  DecodedPointCloud2 cloud;
  cloud.info = layout.info;
  DecodePoints(layout, cloud);
  if (cloud.points.empty()) {
    cursor.Fail("no finite point (" + std::to_string(cloud.dropped_nonfinite) +
                " points with NaN or infinite coordinates)");
  }
  return cloud;
}

StampedPose DecodePoseMessage(const uint8_t* data, size_t size, MessageEncoding encoding,
                              const std::string& type, const std::string& what) {
  if (!IsPoseMessageType(type)) {
    throw InputError(what + ": " + type + " is not a pose message (nav_msgs/Odometry or " +
                     "geometry_msgs/PoseStamped)");
  }
  MessageCursor cursor(data, size, encoding, what);
  return IsOdometryType(type) ? ReadOdometry(cursor) : ReadPoseStamped(cursor);
}

std::vector<FrameTransform> DecodeTfMessage(const uint8_t* data, size_t size,
                                            MessageEncoding encoding, const std::string& what) {
  MessageCursor cursor(data, size, encoding, what);
  // A TransformStamped is at least a header, a child frame and 7 doubles.
  constexpr size_t kMinTransformBytes = 7 * 8;
  const uint32_t count = cursor.Count(kMinTransformBytes, "transforms");
  std::vector<FrameTransform> transforms(count);
  for (FrameTransform& transform : transforms) {
    int64_t stamp_ns = 0;
    ReadHeader(cursor, stamp_ns, transform.parent);
    transform.child = cursor.String("child_frame_id");
    transform.parent_child = ReadPose(cursor);
  }
  return transforms;
}

}  // namespace boicp
