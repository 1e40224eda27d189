#pragma once
// Reading logged drives from ROS bags as topics of serialized messages: ROS 1
// .bag files, ROS 2 bag folders (metadata.yaml with .db3 storage) and ROS 2
// .mcap files. What a message decodes to is ros_messages.hpp's business.
// Every failure throws boicp::InputError with one line naming the file.

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace boicp {

enum class BagStorage { kRos1, kRos2Sqlite, kMcap };

/// "ROS 1 bag", "ROS 2 bag (.db3)", "ROS 2 bag (.mcap)".
std::string BagStorageName(BagStorage storage);

/// How a bag serializes its messages: ROS 1's packed little-endian layout,
/// or ROS 2's CDR (with its 4-byte encapsulation header).
enum class MessageEncoding { kRos1, kCdr };

struct BagTopic {
  std::string name;  // "/points"
  std::string
      type;  // as stored: "sensor_msgs/PointCloud2" (ROS 1), "sensor_msgs/msg/PointCloud2" (ROS 2)
  uint64_t messages = 0;
};

/// Where one message sits in its bag. Only a reader of the same bag file can
/// read it; callers keep it and pass it back, they do not interpret it.
struct BagMessageRef {
  int64_t log_time_ns = 0;  // when the recorder wrote it (not the header stamp)
  uint64_t position = 0;    // the reader's own locator
  uint64_t offset = 0;      // the reader's own locator
  uint64_t size = 0;        // serialized bytes, as the bag declares them
  uint32_t file = 0;        // which storage file of a split ROS 2 bag holds it
};

/// Limits applied before anything is allocated from a size the file declares.
struct BagLimits {
  /// A message (or a chunk's decompressed size) over this is refused: 1 GiB.
  uint64_t max_message_bytes = uint64_t{1} << 30;
};

/// An open bag. Opening reads only what Read needs (headers, an index when
/// there is one); Topics, TimeRange and Messages may read the whole bag.
/// Not thread-safe: open one reader per thread.
class BagReader {
 public:
  virtual ~BagReader() = default;
  virtual const std::string& path() const = 0;
  virtual BagStorage storage() const = 0;
  virtual MessageEncoding encoding() const = 0;
  /// Every topic with its type and message count, sorted by name.
  virtual std::vector<BagTopic> Topics() = 0;
  /// First and last log time in nanoseconds; {0, 0} for a bag with no message.
  virtual std::pair<int64_t, int64_t> TimeRange() = 0;
  /// `topic`'s messages in log-time order (ties in the bag's order); empty
  /// for a topic the bag does not have.
  virtual std::vector<BagMessageRef> Messages(const std::string& topic) = 0;
  /// One message's serialized bytes, exactly as the recorder stored them.
  virtual std::vector<uint8_t> Read(const BagMessageRef& message) = 0;
};

/// True when `path` names a bag: a file ending in .bag, .mcap or .db3 (any
/// case), or a folder holding metadata.yaml.
bool IsBagPath(const std::string& path);

/// Opens a bag, its storage from the path as IsBagPath tells it (a ROS 2
/// folder: its metadata.yaml's storage_identifier, sqlite3 or mcap; a folder
/// split into several storage files reads as one bag). Throws
/// InputError naming the file and the problem (missing, not a bag, truncated,
/// an unsupported compression or storage).
std::unique_ptr<BagReader> OpenBag(const std::string& path, const BagLimits& limits = {});

}  // namespace boicp
