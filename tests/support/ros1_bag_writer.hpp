#pragma once
// Test-only: writing ROS 1 bags (format 2.0) of already serialized messages
// through rosbag_storage, with each connection's real md5sum and message
// definition for the types boicp reads, so no ROS message package or Python
// is needed.

#include <cstdint>
#include <string>
#include <vector>

namespace boicp::test {

/// One message to write: its topic and type ("sensor_msgs/PointCloud2",
/// "nav_msgs/Odometry", "geometry_msgs/PoseStamped", or another type, written
/// with md5sum "*"), the log time and its ROS 1 serialized bytes.
struct Ros1BagMessage {
  std::string topic;
  std::string type;
  int64_t log_time_ns = 0;
  std::vector<uint8_t> data;
};

enum class Ros1BagCompression { kNone, kBz2, kLz4 };

/// Writes `messages` in order to a new bag at `path`, in chunks of about
/// `chunk_bytes` compressed as asked. Throws whatever rosbag throws.
void WriteRos1Bag(const std::string& path, const std::vector<Ros1BagMessage>& messages,
                  Ros1BagCompression compression = Ros1BagCompression::kNone,
                  uint32_t chunk_bytes = 768 * 1024);

}  // namespace boicp::test
