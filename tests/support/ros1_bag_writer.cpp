#include "ros1_bag_writer.hpp"

#include <rosbag/bag.h>

#include <cstring>
#include <map>

namespace boicp::test {
namespace {

// What a ROS 1 connection declares about a type: its md5sum and definition
// (comments left out of the definitions; nothing reads them).
struct TypeDescription {
  const char* md5sum;
  const char* definition;
};

constexpr char kHeaderDefinition[] =
    "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n";
constexpr char kPoseDefinition[] =
    "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n"
    "================================================================================\n"
    "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n"
    "================================================================================\n"
    "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n";
constexpr char kSeparator[] =
    "================================================================================\n";

const std::map<std::string, std::string>& Definitions() {
  static const std::map<std::string, std::string> definitions = {
      {"sensor_msgs/PointCloud2",
       std::string("Header header\nuint32 height\nuint32 width\nPointField[] fields\n"
                   "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\n"
                   "bool is_dense\n\n") +
           kSeparator + kHeaderDefinition + "\n" + kSeparator +
           "MSG: sensor_msgs/PointField\nuint8 INT8    = 1\nuint8 UINT8   = 2\n"
           "uint8 INT16   = 3\nuint8 UINT16  = 4\nuint8 INT32   = 5\nuint8 UINT32  = 6\n"
           "uint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\nstring name\nuint32 offset\nuint8  datatype\n"
           "uint32 count\n"},
      {"nav_msgs/Odometry",
       std::string("Header header\nstring child_frame_id\n"
                   "geometry_msgs/PoseWithCovariance pose\n"
                   "geometry_msgs/TwistWithCovariance twist\n\n") +
           kSeparator + kHeaderDefinition + "\n" + kSeparator +
           "MSG: geometry_msgs/PoseWithCovariance\nPose pose\nfloat64[36] covariance\n\n" +
           kSeparator + kPoseDefinition + "\n" + kSeparator +
           "MSG: geometry_msgs/TwistWithCovariance\nTwist twist\nfloat64[36] covariance\n\n" +
           kSeparator + "MSG: geometry_msgs/Twist\nVector3  linear\nVector3  angular\n\n" +
           kSeparator + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/PoseStamped", std::string("Header header\nPose pose\n\n") + kSeparator +
                                        kHeaderDefinition + "\n" + kSeparator + kPoseDefinition},
  };
  return definitions;
}

const std::map<std::string, std::string>& Md5Sums() {
  static const std::map<std::string, std::string> md5sums = {
      {"sensor_msgs/PointCloud2", "1158d486dd51d683ce2f1be655c3c181"},
      {"nav_msgs/Odometry", "cd5e73d190d741a2f92e81eda573aca7"},
      {"geometry_msgs/PoseStamped", "d3812c3cbc69362b77dc0b19b345f8f5"},
  };
  return md5sums;
}

std::string Lookup(const std::map<std::string, std::string>& table, const std::string& type,
                   const char* otherwise) {
  const auto it = table.find(type);
  return it == table.end() ? otherwise : it->second;
}

}  // namespace

/// A message already serialized, carrying its own type description: what
/// rosbag::Bag::write needs from a message (traits and a serializer below).
struct RawRos1Message {
  std::string type;
  std::string md5sum;
  std::string definition;
  const std::vector<uint8_t>* data;
};

}  // namespace boicp::test

namespace ros {
namespace message_traits {

template <>
struct MD5Sum<boicp::test::RawRos1Message> {
  static const char* value(const boicp::test::RawRos1Message& m) { return m.md5sum.c_str(); }
  static const char* value() { return "*"; }
};

template <>
struct DataType<boicp::test::RawRos1Message> {
  static const char* value(const boicp::test::RawRos1Message& m) { return m.type.c_str(); }
  static const char* value() { return "*"; }
};

template <>
struct Definition<boicp::test::RawRos1Message> {
  static const char* value(const boicp::test::RawRos1Message& m) { return m.definition.c_str(); }
  static const char* value() { return ""; }
};

}  // namespace message_traits

namespace serialization {

template <>
struct Serializer<boicp::test::RawRos1Message> {
  template <typename Stream>
  static void write(Stream& stream, const boicp::test::RawRos1Message& m) {
    const uint32_t size = serializedLength(m);
    if (size > 0) std::memcpy(stream.advance(size), m.data->data(), size);
  }

  static uint32_t serializedLength(const boicp::test::RawRos1Message& m) {
    return static_cast<uint32_t>(m.data->size());
  }
};

}  // namespace serialization
}  // namespace ros

namespace boicp::test {

void WriteRos1Bag(const std::string& path, const std::vector<Ros1BagMessage>& messages,
                  Ros1BagCompression compression, uint32_t chunk_bytes) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setChunkThreshold(chunk_bytes);
  switch (compression) {
    case Ros1BagCompression::kNone:
      bag.setCompression(rosbag::compression::Uncompressed);
      break;
    case Ros1BagCompression::kBz2:
      bag.setCompression(rosbag::compression::BZ2);
      break;
    case Ros1BagCompression::kLz4:
      bag.setCompression(rosbag::compression::LZ4);
      break;
  }
  for (const Ros1BagMessage& message : messages) {
    const RawRos1Message raw{message.type, Lookup(Md5Sums(), message.type, "*"),
                             Lookup(Definitions(), message.type, ""), &message.data};
    const auto sec = static_cast<uint32_t>(message.log_time_ns / 1000000000);
    const auto nsec = static_cast<uint32_t>(message.log_time_ns % 1000000000);
    bag.write(message.topic, ros::Time(sec, nsec), raw);
  }
  bag.close();
}

}  // namespace boicp::test
