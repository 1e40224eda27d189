// Scans that are PointCloud2 messages inside a bag: the bag is opened for
// each load, so that loads on several threads share nothing.

#include <algorithm>
#include <cstdio>

#include "boicp/io/ros_messages.hpp"
#include "io/io_readers.hpp"

namespace boicp::io_detail {
namespace {

const BagMessageRef& RequireMessage(const std::string& path, const LoadOptions& options) {
  if (!options.bag_message) {
    throw InputError(path + ": a scan inside a bag needs its message's place in the bag");
  }
  return *options.bag_message;
}

// "drive.bag: the message logged at 1317384506.402 s", to name a scan in errors.
std::string MessageName(const std::string& path, const BagMessageRef& message) {
  char at[48];
  std::snprintf(at, sizeof at, "%.3f", static_cast<double>(message.log_time_ns) * 1e-9);
  return path + ": the message logged at " + at + " s";
}

}  // namespace

Points ReadRosMessage(const std::string& path, const LoadOptions& options) {
  const BagMessageRef& message = RequireMessage(path, options);
  const std::unique_ptr<BagReader> bag = OpenBag(path);
  const std::vector<uint8_t> data = bag->Read(message);
  return DecodePointCloud2(data.data(), data.size(), bag->encoding(), options.max_points,
                           MessageName(path, message))
      .points;
}

uint64_t RosMessageBound(const std::string& path, const LoadOptions& options) {
  const BagMessageRef& message = RequireMessage(path, options);
  // A point takes at least 12 bytes of the message (three float32).
  const uint64_t points = std::min<uint64_t>(message.size / 12, options.max_points);
  return 2 * message.size + points * sizeof(Point);
}

}  // namespace boicp::io_detail
