// Decoding PointCloud2, Odometry, PoseStamped and TFMessage from both serializations:
// exact round trips through the test encoders for every layout option, and
// malformed messages (truncated, lying sizes, bad fields, bad quaternions)
// refused with one InputError line naming the message.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/input_error.hpp"
#include "../support/ros_message_writer.hpp"
#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/ros_messages.hpp"

namespace boicp {
namespace {

using test::InputErrorMessage;
using test::PointCloud2Options;
using ::testing::HasSubstr;

constexpr uint64_t kManyPoints = 1000000;
constexpr int64_t kStamp = 1700000000123456789;

Points SamplePoints(size_t count) {
  Points points;
  for (size_t i = 0; i < count; ++i) {
    const double k = static_cast<double>(i);
    points.emplace_back(0.5 * k - 3.25, -1.75 * k, 0.125 * k + 10.0);  // exact in float32
  }
  return points;
}

DecodedPointCloud2 Decode(const std::vector<uint8_t>& bytes, MessageEncoding encoding,
                          uint64_t max_points = kManyPoints) {
  return DecodePointCloud2(bytes.data(), bytes.size(), encoding, max_points, "/points#3");
}

std::string DecodeError(const std::vector<uint8_t>& bytes, MessageEncoding encoding,
                        uint64_t max_points = kManyPoints) {
  return InputErrorMessage([&] { Decode(bytes, encoding, max_points); });
}

struct CloudCase {
  const char* name;
  MessageEncoding encoding;
  PointCloud2Options options;
};

std::vector<CloudCase> CloudCases() {
  std::vector<CloudCase> cases;
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    PointCloud2Options o;
    cases.push_back({"plain", encoding, o});
    o = {};
    o.float64 = true;
    cases.push_back({"float64", encoding, o});
    o = {};
    o.big_endian = true;
    cases.push_back({"big_endian", encoding, o});
    o = {};
    o.float64 = true;
    o.big_endian = true;
    cases.push_back({"float64_big_endian", encoding, o});
    o = {};
    o.intensity = true;
    o.point_padding = 5;
    cases.push_back({"intensity_and_padding", encoding, o});
    o = {};
    o.intensity = true;
    o.float64 = true;
    cases.push_back({"float64_at_odd_offset", encoding, o});
    o = {};
    o.height = 4;
    o.row_padding = 3;
    cases.push_back({"rows_with_padding", encoding, o});
    o = {};
    o.nan_points = 4;
    o.height = 2;
    cases.push_back({"nan_points", encoding, o});
  }
  return cases;
}

TEST(RosMessages, TypeNamesInBothStyles) {
  EXPECT_TRUE(IsPointCloud2Type("sensor_msgs/PointCloud2"));
  EXPECT_TRUE(IsPointCloud2Type("sensor_msgs/msg/PointCloud2"));
  EXPECT_FALSE(IsPointCloud2Type("sensor_msgs/PointCloud"));
  for (const char* type : {"nav_msgs/Odometry", "nav_msgs/msg/Odometry",
                           "geometry_msgs/PoseStamped", "geometry_msgs/msg/PoseStamped"}) {
    EXPECT_TRUE(IsPoseMessageType(type)) << type;
  }
  EXPECT_FALSE(IsPoseMessageType("geometry_msgs/Pose"));
  EXPECT_FALSE(IsPoseMessageType("sensor_msgs/PointCloud2"));
  EXPECT_TRUE(IsTfMessageType("tf2_msgs/TFMessage"));
  EXPECT_TRUE(IsTfMessageType("tf2_msgs/msg/TFMessage"));
  EXPECT_FALSE(IsTfMessageType("geometry_msgs/TransformStamped"));
}

TEST(RosMessages, PointCloud2RoundTripsEveryLayout) {
  const Points points = SamplePoints(12);
  for (const CloudCase& c : CloudCases()) {
    SCOPED_TRACE(std::string(c.name) + (c.encoding == MessageEncoding::kCdr ? " cdr" : " ros1"));
    const auto bytes = test::EncodePointCloud2(points, kStamp, "velodyne", c.encoding, c.options);
    const DecodedPointCloud2 cloud = Decode(bytes, c.encoding);
    EXPECT_EQ(cloud.info.stamp_ns, kStamp);
    EXPECT_EQ(cloud.info.frame_id, "velodyne");
    EXPECT_EQ(cloud.info.points, points.size() + c.options.nan_points);
    EXPECT_EQ(cloud.dropped_nonfinite, c.options.nan_points);
    ASSERT_EQ(cloud.points.size(), points.size());
    for (size_t i = 0; i < points.size(); ++i) EXPECT_EQ(cloud.points[i], points[i]) << i;

    const PointCloud2Info info =
        PeekPointCloud2(bytes.data(), bytes.size(), c.encoding, "/points#3");
    EXPECT_EQ(info.stamp_ns, kStamp);
    EXPECT_EQ(info.frame_id, "velodyne");
    EXPECT_EQ(info.points, cloud.info.points);
  }
}

TEST(RosMessages, Float64KeepsFullPrecision) {
  const Points points = {Point(0.1, 1e-9, 123456.789012345)};
  PointCloud2Options options;
  options.float64 = true;
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    const auto bytes = test::EncodePointCloud2(points, 0, "f", encoding, options);
    EXPECT_EQ(Decode(bytes, encoding).points.front(), points.front());
  }
}

TEST(RosMessages, CdrStringsCountTheirNulAndPrimitivesAlign) {
  // A 1-character frame_id in CDR: encapsulation 4, sec 4, nsec 4, length 4
  // (= 2), "f\0" at 16, then height aligned to 4 counted after the
  // encapsulation: two padding bytes, height at 20.
  const auto bytes = test::EncodePointCloud2(SamplePoints(1), 0, "f", MessageEncoding::kCdr);
  ASSERT_GT(bytes.size(), 24u);
  EXPECT_EQ(bytes[1], 0x01);
  EXPECT_EQ(bytes[12], 2);
  EXPECT_EQ(bytes[16], 'f');
  EXPECT_EQ(bytes[17], 0);
  EXPECT_EQ(bytes[20], 1);  // height
}

TEST(RosMessages, PointCloud2TruncatedAtEveryLengthIsRefused) {
  PointCloud2Options options;
  options.intensity = true;
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    const auto bytes = test::EncodePointCloud2(SamplePoints(3), kStamp, "lidar", encoding, options);
    for (size_t length = 0; length < bytes.size(); ++length) {
      const std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + length);
      const std::string message = DecodeError(prefix, encoding);
      EXPECT_THAT(message, HasSubstr("/points#3: ")) << length;
      EXPECT_EQ(message.find('\n'), std::string::npos);
      EXPECT_FALSE(InputErrorMessage([&] {
                     PeekPointCloud2(prefix.data(), prefix.size(), encoding, "/points#3");
                   }).empty());
    }
  }
}

TEST(RosMessages, PointCloud2WithLyingSizesIsRefused) {
  const Points points = SamplePoints(4);
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    PointCloud2Options o;
    o.width = 5;  // one point more than the data holds
    EXPECT_THAT(DecodeError(test::EncodePointCloud2(points, 0, "f", encoding, o), encoding),
                HasSubstr("data bytes"));
    o = {};
    o.width = 0xFFFFFFFF;  // width x point_step would overflow 32 bits; no point limit
    EXPECT_THAT(DecodeError(test::EncodePointCloud2(points, 0, "f", encoding, o), encoding,
                            std::numeric_limits<uint64_t>::max()),
                HasSubstr("data bytes"));
    o = {};
    o.point_step = 8;  // under the 12 bytes x, y, z take
    EXPECT_THAT(DecodeError(test::EncodePointCloud2(points, 0, "f", encoding, o), encoding),
                HasSubstr("does not fit in point_step 8"));
    o = {};
    o.x_offset = 10;  // x ends past point_step 12
    EXPECT_THAT(DecodeError(test::EncodePointCloud2(points, 0, "f", encoding, o), encoding),
                HasSubstr("field 'x' at offset 10"));
    o = {};
    o.x_offset = 0xFFFFFFFE;  // offset + size would overflow 32 bits
    EXPECT_THAT(DecodeError(test::EncodePointCloud2(points, 0, "f", encoding, o), encoding),
                HasSubstr("does not fit"));
    o = {};
    o.height = 2;
    o.row_step = 12;  // a row of 2 points needs 24
    EXPECT_THAT(DecodeError(test::EncodePointCloud2(points, 0, "f", encoding, o), encoding),
                HasSubstr("row_step 12 is less than"));
  }
}

TEST(RosMessages, PointCloud2WithBadFieldsIsRefused) {
  const Points points = SamplePoints(2);
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    PointCloud2Options o;
    o.omit_z = true;
    EXPECT_THAT(DecodeError(test::EncodePointCloud2(points, 0, "f", encoding, o), encoding),
                HasSubstr("no 'z' field"));
    o = {};
    o.x_datatype = 5;  // INT32
    EXPECT_THAT(DecodeError(test::EncodePointCloud2(points, 0, "f", encoding, o), encoding),
                HasSubstr("field 'x' has datatype 5"));
  }
}

TEST(RosMessages, PointCloud2WithoutFinitePointsIsRefused) {
  PointCloud2Options o;
  o.nan_points = 3;
  const auto bytes = test::EncodePointCloud2({}, 0, "f", MessageEncoding::kRos1, o);
  EXPECT_THAT(DecodeError(bytes, MessageEncoding::kRos1), HasSubstr("no finite point"));
  o.nan_points = 0;
  const auto empty = test::EncodePointCloud2({}, 0, "f", MessageEncoding::kRos1, o);
  EXPECT_THAT(DecodeError(empty, MessageEncoding::kRos1), HasSubstr("no points"));
}

TEST(RosMessages, HugeDeclaredCloudIsRefusedBeforeAllocating) {
  PointCloud2Options o;
  o.width = 0xFFFFFFFF;
  o.height = 1;
  const auto bytes = test::EncodePointCloud2(SamplePoints(1), 0, "f", MessageEncoding::kCdr, o);
  try {
    Decode(bytes, MessageEncoding::kCdr, 1000);
    FAIL() << "expected PointLimitError";
  } catch (const PointLimitError& e) {
    EXPECT_EQ(e.points(), 0xFFFFFFFFu);
    EXPECT_EQ(e.limit(), 1000u);
    EXPECT_THAT(e.what(), HasSubstr("/points#3"));
  }
}

TEST(RosMessages, UnsupportedCdrEncapsulationIsRefused) {
  auto bytes = test::EncodePointCloud2(SamplePoints(1), 0, "f", MessageEncoding::kCdr);
  bytes[1] = 0x03;  // PL_CDR_LE
  EXPECT_THAT(DecodeError(bytes, MessageEncoding::kCdr), HasSubstr("unsupported CDR"));
}

TEST(RosMessages, FieldCountTooLargeForTheMessageIsRefused) {
  auto bytes = test::EncodePointCloud2(SamplePoints(1), 0, "", MessageEncoding::kRos1);
  // ROS 1: seq 4, sec 4, nsec 4, frame_id length 4, height 4, width 4, then the field count.
  const size_t at = 24;
  ASSERT_EQ(bytes[at], 3);
  bytes[at] = 0xFF;
  bytes[at + 3] = 0x7F;
  EXPECT_THAT(DecodeError(bytes, MessageEncoding::kRos1), HasSubstr("fields declares"));
}

Transform SamplePose() {
  Transform pose = Transform::Identity();
  pose.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.topRightCorner<3, 1>() = Eigen::Vector3d(1.5, -2.25, 0.75);
  return pose;
}

StampedPose DecodePose(const std::vector<uint8_t>& bytes, MessageEncoding encoding,
                       const std::string& type) {
  return DecodePoseMessage(bytes.data(), bytes.size(), encoding, type, "/odom#1");
}

TEST(RosMessages, PoseMessagesRoundTrip) {
  const Transform pose = SamplePose();
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    const auto odometry = test::EncodeOdometry(pose, kStamp, "odom", encoding);
    const auto stamped = test::EncodePoseStamped(pose, kStamp, "map", encoding);
    for (const char* type : {"nav_msgs/Odometry", "nav_msgs/msg/Odometry"}) {
      const StampedPose decoded = DecodePose(odometry, encoding, type);
      EXPECT_EQ(decoded.stamp_ns, kStamp);
      EXPECT_EQ(decoded.frame_id, "odom");
      EXPECT_EQ(decoded.child_frame_id, "base_link");
      EXPECT_TRUE(decoded.pose.isApprox(pose, 1e-12)) << decoded.pose;
    }
    for (const char* type : {"geometry_msgs/PoseStamped", "geometry_msgs/msg/PoseStamped"}) {
      const StampedPose decoded = DecodePose(stamped, encoding, type);
      EXPECT_EQ(decoded.stamp_ns, kStamp);
      EXPECT_EQ(decoded.frame_id, "map");
      EXPECT_TRUE(decoded.pose.isApprox(pose, 1e-12)) << decoded.pose;
    }
  }
}

TEST(RosMessages, NearUnitQuaternionIsNormalised) {
  const Eigen::Vector4d q(0.0, 0.0, std::sin(0.25), std::cos(0.25));
  const auto bytes = test::EncodePoseStamped(Transform::Identity(), 0, "map",
                                             MessageEncoding::kRos1, Eigen::Vector4d(1.05 * q));
  const StampedPose decoded =
      DecodePose(bytes, MessageEncoding::kRos1, "geometry_msgs/PoseStamped");
  const Eigen::Matrix3d rotation = decoded.pose.topLeftCorner<3, 3>();
  EXPECT_TRUE((rotation * rotation.transpose()).isIdentity(1e-12));
  EXPECT_NEAR(std::atan2(rotation(1, 0), rotation(0, 0)), 0.5, 1e-12);
}

TEST(RosMessages, BadQuaternionsAreRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Eigen::Vector4d& q : {Eigen::Vector4d(0, 0, 0, 0), Eigen::Vector4d(0, 0, 0, 1.2),
                                   Eigen::Vector4d(nan, 0, 0, 1)}) {
    for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
      const auto bytes = test::EncodeOdometry(Transform::Identity(), 0, "odom", encoding, q);
      EXPECT_THAT(InputErrorMessage([&] { DecodePose(bytes, encoding, "nav_msgs/Odometry"); }),
                  HasSubstr("/odom#1: pose orientation"))
          << q.transpose();
    }
  }
}

TEST(RosMessages, PoseMessagesTruncatedAtEveryLengthAreRefused) {
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    const auto odometry = test::EncodeOdometry(SamplePose(), kStamp, "odom", encoding);
    const auto stamped = test::EncodePoseStamped(SamplePose(), kStamp, "map", encoding);
    for (size_t length = 0; length < odometry.size(); ++length) {
      const std::vector<uint8_t> prefix(odometry.begin(), odometry.begin() + length);
      EXPECT_THAT(InputErrorMessage([&] { DecodePose(prefix, encoding, "nav_msgs/Odometry"); }),
                  HasSubstr("/odom#1: "))
          << length;
    }
    for (size_t length = 0; length < stamped.size(); ++length) {
      const std::vector<uint8_t> prefix(stamped.begin(), stamped.begin() + length);
      EXPECT_THAT(
          InputErrorMessage([&] { DecodePose(prefix, encoding, "geometry_msgs/PoseStamped"); }),
          HasSubstr("/odom#1: "))
          << length;
    }
  }
}

TEST(RosMessages, TfMessagesRoundTripAndTruncatedOnesAreRefused) {
  Transform mount = SamplePose();
  const std::vector<FrameTransform> transforms = {{"base_link", "velodyne", mount},
                                                  {"/base_link", "imu", Transform::Identity()}};
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    const auto bytes = test::EncodeTfMessage(transforms, kStamp, encoding);
    const std::vector<FrameTransform> decoded =
        DecodeTfMessage(bytes.data(), bytes.size(), encoding, "/tf_static#1");
    ASSERT_EQ(decoded.size(), 2u);
    EXPECT_EQ(decoded[0].parent, "base_link");
    EXPECT_EQ(decoded[0].child, "velodyne");
    EXPECT_TRUE(decoded[0].parent_child.isApprox(mount, 1e-12));
    EXPECT_EQ(decoded[1].parent, "/base_link");
    EXPECT_TRUE(decoded[1].parent_child.isIdentity(1e-15));
    for (size_t length = 0; length < bytes.size(); ++length) {
      EXPECT_THAT(InputErrorMessage(
                      [&] { DecodeTfMessage(bytes.data(), length, encoding, "/tf_static#1"); }),
                  HasSubstr("/tf_static#1: "))
          << length;
    }
  }
}

TEST(RosMessages, UnknownPoseTypeIsRefused) {
  const auto bytes = test::EncodePoseStamped(SamplePose(), 0, "map", MessageEncoding::kRos1);
  EXPECT_THAT(
      InputErrorMessage([&] { DecodePose(bytes, MessageEncoding::kRos1, "tf2_msgs/TFMessage"); }),
      HasSubstr("is not a pose message"));
}

}  // namespace
}  // namespace boicp
