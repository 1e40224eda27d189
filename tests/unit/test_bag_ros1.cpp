// ROS 1 bags through OpenBag: bags written with rosbag_storage (uncompressed,
// bz2 and lz4 chunks) read back exactly, and broken files refused with one
// InputError line naming the file.

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/input_error.hpp"
#include "../support/ros1_bag_writer.hpp"
#include "../support/ros_message_writer.hpp"
#include "boicp/io/bag_reader.hpp"
#include "boicp/io/ros_messages.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;
using test::InputErrorMessage;
using test::Ros1BagCompression;
using test::Ros1BagMessage;
using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr int64_t kStart = 1317384506000000000;  // a KITTI drive's first second
constexpr int64_t kScanPeriod = 100000000;

class BagRos1Test : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("boicp-bag-ros1-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // Four clouds on /points and eight odometry messages on /odom, interleaved
  // in log time, plus a second /odom message at the same time as another.
  static std::vector<Ros1BagMessage> Drive() {
    std::vector<Ros1BagMessage> messages;
    for (int i = 0; i < 8; ++i) {
      const int64_t t = kStart + i * kScanPeriod / 2;
      if (i % 2 == 0) {
        Points points;
        for (int k = 0; k < 50; ++k) points.emplace_back(i + 0.25 * k, -k, 0.5 * i);
        messages.push_back(
            {"/points", "sensor_msgs/PointCloud2", t,
             test::EncodePointCloud2(points, t - 1000, "velodyne", MessageEncoding::kRos1)});
      }
      Transform pose = Transform::Identity();
      pose(0, 3) = i;
      messages.push_back({"/odom", "nav_msgs/Odometry", t + 10,
                          test::EncodeOdometry(pose, t, "odom", MessageEncoding::kRos1)});
    }
    Transform pose = Transform::Identity();
    pose(1, 3) = 42;
    messages.push_back({"/odom", "nav_msgs/Odometry", kStart + 10,
                        test::EncodeOdometry(pose, kStart, "odom", MessageEncoding::kRos1)});
    return messages;
  }

  static std::vector<uint8_t> FileBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  static void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  }

  void ExpectReadsBack(const std::string& path, const std::vector<Ros1BagMessage>& written) {
    std::unique_ptr<BagReader> bag = OpenBag(path);
    EXPECT_EQ(bag->path(), path);
    EXPECT_EQ(bag->storage(), BagStorage::kRos1);
    EXPECT_EQ(bag->encoding(), MessageEncoding::kRos1);

    const std::vector<BagTopic> topics = bag->Topics();
    ASSERT_EQ(topics.size(), 2u);
    EXPECT_EQ(topics[0].name, "/odom");
    EXPECT_EQ(topics[0].type, "nav_msgs/Odometry");
    EXPECT_EQ(topics[0].messages, 9u);
    EXPECT_EQ(topics[1].name, "/points");
    EXPECT_EQ(topics[1].type, "sensor_msgs/PointCloud2");
    EXPECT_EQ(topics[1].messages, 4u);
    EXPECT_EQ(bag->TimeRange(), std::make_pair(kStart, kStart + 7 * kScanPeriod / 2 + 10));
    EXPECT_TRUE(bag->Messages("/nothing").empty());

    for (const std::string topic : {"/points", "/odom"}) {
      // The written messages of this topic, by log time (ties in write order).
      std::vector<const Ros1BagMessage*> expected;
      for (const Ros1BagMessage& m : written) {
        if (m.topic == topic) expected.push_back(&m);
      }
      std::stable_sort(expected.begin(), expected.end(),
                       [](auto* a, auto* b) { return a->log_time_ns < b->log_time_ns; });
      const std::vector<BagMessageRef> refs = bag->Messages(topic);
      ASSERT_EQ(refs.size(), expected.size()) << topic;
      for (size_t i = 0; i < refs.size(); ++i) {
        EXPECT_EQ(refs[i].log_time_ns, expected[i]->log_time_ns) << topic << i;
        EXPECT_GE(refs[i].size, expected[i]->data.size()) << topic << i;
        // An upper bound: it may take in a connection record written in the chunk.
        EXPECT_LE(refs[i].size, expected[i]->data.size() + 4096) << topic << i;
        EXPECT_EQ(bag->Read(refs[i]), expected[i]->data) << topic << i;
      }
      // A fresh reader finds a message from its ref alone, in any order.
      std::unique_ptr<BagReader> fresh = OpenBag(path);
      EXPECT_EQ(fresh->Read(refs.back()), expected.back()->data);
      EXPECT_EQ(fresh->Read(refs.front()), expected.front()->data);
    }
  }

  fs::path dir_;
};

TEST_F(BagRos1Test, UncompressedBagReadsBack) {
  const auto messages = Drive();
  test::WriteRos1Bag(Path("drive.bag"), messages);
  ExpectReadsBack(Path("drive.bag"), messages);
}

TEST_F(BagRos1Test, SmallChunksReadBack) {
  const auto messages = Drive();
  test::WriteRos1Bag(Path("drive.bag"), messages, Ros1BagCompression::kNone, 1000);
  ExpectReadsBack(Path("drive.bag"), messages);
}

TEST_F(BagRos1Test, Bz2BagReadsBack) {
  const auto messages = Drive();
  test::WriteRos1Bag(Path("drive.bag"), messages, Ros1BagCompression::kBz2, 4000);
  ExpectReadsBack(Path("drive.bag"), messages);
}

TEST_F(BagRos1Test, Lz4BagReadsBack) {
  const auto messages = Drive();
  test::WriteRos1Bag(Path("drive.bag"), messages, Ros1BagCompression::kLz4, 4000);
  ExpectReadsBack(Path("drive.bag"), messages);
}

TEST_F(BagRos1Test, ScansDecodeFromTheBag) {
  test::WriteRos1Bag(Path("drive.bag"), Drive(), Ros1BagCompression::kLz4);
  std::unique_ptr<BagReader> bag = OpenBag(Path("drive.bag"));
  const auto refs = bag->Messages("/points");
  ASSERT_FALSE(refs.empty());
  const auto data = bag->Read(refs[1]);
  const DecodedPointCloud2 cloud =
      DecodePointCloud2(data.data(), data.size(), bag->encoding(), 1000, "scan");
  EXPECT_EQ(cloud.points.size(), 50u);
  EXPECT_EQ(cloud.info.frame_id, "velodyne");
  const auto odom = bag->Read(bag->Messages("/odom")[1]);
  const StampedPose pose =
      DecodePoseMessage(odom.data(), odom.size(), bag->encoding(), "nav_msgs/Odometry", "odom");
  EXPECT_EQ(pose.pose(1, 3), 42);  // the second message at the first time
}

TEST_F(BagRos1Test, EmptyBagHasNoTopics) {
  test::WriteRos1Bag(Path("empty.bag"), {});
  std::unique_ptr<BagReader> bag = OpenBag(Path("empty.bag"));
  EXPECT_TRUE(bag->Topics().empty());
  EXPECT_EQ(bag->TimeRange(), std::make_pair(int64_t{0}, int64_t{0}));
}

TEST_F(BagRos1Test, MissingFileIsRefused) {
  EXPECT_THAT(InputErrorMessage([&] { OpenBag(Path("missing.bag")); }),
              StartsWith(Path("missing.bag") + ": "));
}

TEST_F(BagRos1Test, FileThatIsNotABagIsRefused) {
  WriteBytes(Path("scan.bag"), {'p', 'l', 'y', '\n', 'f', 'o', 'r', 'm', 'a', 't'});
  EXPECT_THAT(InputErrorMessage([&] { OpenBag(Path("scan.bag")); }),
              HasSubstr("scan.bag: not a ROS 1 bag"));
  WriteBytes(Path("old.bag"), std::vector<uint8_t>{'#', 'R', 'O', 'S', 'B', 'A', 'G', ' ', 'V', '1',
                                                   '.', '2', '\n'});
  EXPECT_THAT(InputErrorMessage([&] { OpenBag(Path("old.bag")); }),
              HasSubstr("old.bag: unsupported ROS 1 bag version"));
  WriteBytes(Path("empty.bag"), {});
  EXPECT_THAT(InputErrorMessage([&] { OpenBag(Path("empty.bag")); }),
              HasSubstr("empty.bag: not a ROS 1 bag"));
}

// Every prefix of a bag is refused at open or, when the index survives (it
// cannot: it is at the end), when read; never a crash or another exception.
TEST_F(BagRos1Test, TruncatedBagIsRefusedAtEveryLength) {
  for (Ros1BagCompression compression :
       {Ros1BagCompression::kNone, Ros1BagCompression::kBz2, Ros1BagCompression::kLz4}) {
    std::vector<Ros1BagMessage> messages = Drive();
    messages.resize(3);
    test::WriteRos1Bag(Path("full.bag"), messages, compression, 1500);
    const std::vector<uint8_t> bytes = FileBytes(Path("full.bag"));
    for (size_t length = 0; length < bytes.size(); length += (length < 64 ? 1 : 13)) {
      WriteBytes(Path("cut.bag"), std::vector<uint8_t>(bytes.begin(), bytes.begin() + length));
      const std::string message = InputErrorMessage([&] { OpenBag(Path("cut.bag")); });
      EXPECT_THAT(message, StartsWith(Path("cut.bag") + ": ")) << length;
      EXPECT_EQ(message.find('\n'), std::string::npos) << length;
    }
  }
}

// Unindexed bags (a recording cut short) and chunks that say they are huge.
TEST_F(BagRos1Test, UnindexedAndOversizedBagsAreRefused) {
  std::vector<Ros1BagMessage> messages = Drive();
  test::WriteRos1Bag(Path("drive.bag"), messages);
  std::vector<uint8_t> bytes = FileBytes(Path("drive.bag"));

  // The file header's index_pos field: "index_pos=" then 8 bytes.
  const std::string key = "index_pos=";
  const auto at = std::search(bytes.begin(), bytes.end(), key.begin(), key.end());
  ASSERT_NE(at, bytes.end());
  std::vector<uint8_t> unindexed = bytes;
  std::fill_n(unindexed.begin() + (at - bytes.begin()) + key.size(), 8, 0);
  WriteBytes(Path("unindexed.bag"), unindexed);
  EXPECT_THAT(InputErrorMessage([&] { OpenBag(Path("unindexed.bag")); }),
              HasSubstr("rosbag reindex"));

  BagLimits small;
  small.max_message_bytes = 1000;
  EXPECT_THAT(InputErrorMessage([&] { OpenBag(Path("drive.bag"), small); }),
              HasSubstr("over the limit of 1000"));
}

// Bytes flipped inside a message record of an uncompressed chunk are caught
// before rosbag_storage reads the record.
TEST_F(BagRos1Test, CorruptMessageRecordIsRefused) {
  std::vector<Ros1BagMessage> messages = Drive();
  test::WriteRos1Bag(Path("drive.bag"), messages);
  std::vector<uint8_t> bytes = FileBytes(Path("drive.bag"));
  // The first message record: its header holds "conn" then "op" = 2 (fields
  // sorted by name), so its header length is 21 bytes before "op=\x02".
  const std::string op = std::string("op=") + '\x02';
  const auto at = std::search(bytes.begin(), bytes.end(), op.begin(), op.end());
  ASSERT_NE(at, bytes.end());
  const size_t op_at = static_cast<size_t>(at - bytes.begin());
  ASSERT_EQ(std::string(bytes.begin() + op_at - 13, bytes.begin() + op_at - 8), "conn=");
  bytes[op_at - 21 + 3] = 0x7F;  // the header now claims ~2 GB
  WriteBytes(Path("corrupt.bag"), bytes);
  std::unique_ptr<BagReader> bag = OpenBag(Path("corrupt.bag"));
  size_t refused = 0;
  for (const std::string topic : {"/points", "/odom"}) {
    for (const BagMessageRef& ref : bag->Messages(topic)) {
      try {
        bag->Read(ref);
      } catch (const InputError& e) {
        ++refused;
        EXPECT_THAT(e.what(), StartsWith(Path("corrupt.bag") + ": ")) << e.what();
      }
    }
  }
  EXPECT_EQ(refused, 1u);
}

TEST_F(BagRos1Test, UnknownRefIsRefused) {
  test::WriteRos1Bag(Path("drive.bag"), Drive());
  std::unique_ptr<BagReader> bag = OpenBag(Path("drive.bag"));
  BagMessageRef ref = bag->Messages("/points").front();
  ref.offset = 5;
  EXPECT_THAT(InputErrorMessage([&] { bag->Read(ref); }), HasSubstr("drive.bag: no message"));
  ref.offset = 0;
  ref.position = uint64_t{1} << 40;
  EXPECT_THAT(InputErrorMessage([&] { bag->Read(ref); }), HasSubstr("drive.bag: no message"));
}

}  // namespace
}  // namespace boicp
