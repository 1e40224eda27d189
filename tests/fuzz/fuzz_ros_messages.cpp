// libFuzzer harness: arbitrary bytes as a ROS message. The first byte picks
// the serialization (bit 0: CDR) and the type (bits 1-2: PointCloud2,
// Odometry, PoseStamped); the rest is the message. InputError is the
// documented failure; a decoded cloud must hold only finite points.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "boicp/io/ros_messages.hpp"

namespace {

void RequireFinite(const boicp::DecodedPointCloud2& cloud) {
  if (cloud.points.empty()) {
    std::fprintf(stderr, "DecodePointCloud2 returned no point without throwing\n");
    std::abort();
  }
  for (const boicp::Point& p : cloud.points) {
    if (!p.allFinite()) {
      std::fprintf(stderr, "DecodePointCloud2 returned a non-finite point\n");
      std::abort();
    }
  }
}

void RequireRotation(const boicp::StampedPose& pose) {
  const Eigen::Matrix3d r = pose.pose.topLeftCorner<3, 3>();
  if (!pose.pose.allFinite() || !(r * r.transpose()).isIdentity(1e-9)) {
    std::fprintf(stderr, "DecodePoseMessage returned a pose that is not a rigid transform\n");
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const auto encoding =
      (data[0] & 1) != 0 ? boicp::MessageEncoding::kCdr : boicp::MessageEncoding::kRos1;
  const int kind = (data[0] >> 1) % 3;
  const uint8_t* message = data + 1;
  const size_t bytes = size - 1;
  try {
    if (kind == 0) {
      boicp::PeekPointCloud2(message, bytes, encoding, "fuzz");
      RequireFinite(boicp::DecodePointCloud2(message, bytes, encoding, 1 << 20, "fuzz"));
    } else {
      const char* type = kind == 1 ? "nav_msgs/Odometry" : "geometry_msgs/msg/PoseStamped";
      RequireRotation(boicp::DecodePoseMessage(message, bytes, encoding, type, "fuzz"));
    }
  } catch (const boicp::InputError&) {
    // Malformed input refused with a message (PointLimitError included).
  }
  return 0;
}
