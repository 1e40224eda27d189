// `boicp map`, `info` and `submit` on bags: the same generated drive written
// as a ROS 1 .bag, a ROS 2 .db3 folder and a ROS 2 .mcap file gives the same
// trajectory as the folder of its scans; odometry becomes priors, carried
// to the sensor by /tf_static; bad bags give one error line.

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/files_and_processes.hpp"
#include "../support/ros1_bag_writer.hpp"
#include "../support/ros2_bag_writer.hpp"
#include "../support/ros_message_writer.hpp"
#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/scan_folder.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/io/trajectory_io.hpp"
#ifdef BOICP_TEST_WITH_DAEMON
#include "boicp/rpc/map_builder_client.hpp"
#include "daemon_process.hpp"
#endif

namespace boicp {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::RunCaptured;
using test::RunResult;
using test::Slurp;
using ::testing::HasSubstr;

constexpr int64_t kFirstStamp = 1700000000000000000;  // ns
constexpr int64_t kScanPeriod = 100000000;            // 10 Hz
constexpr int64_t kOdometryPeriod = 50000000;         // 20 Hz

std::string Quick() {
  return " --config A --random-samples 4 --iterations 4 --rotation-bounds 0.2,0.2,3.14159"
         " --resolution 0.3 --seed 5 --threads 2";
}

// One message of a drive, in the recorder's terms.
struct DriveMessage {
  std::string topic, type;
  int64_t stamp_ns = 0;
  Points points;                           // a scan
  Transform pose = Transform::Identity();  // an odometry pose
  std::vector<FrameTransform> transforms;  // a /tf_static message
};

class BagCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_bag_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    MakeGeneratedDrive(5);
  }
  void TearDown() override { fs::remove_all(dir_); }

  RunResult Run(const std::string& args) {
    return RunCaptured(std::string(BOICP_CLI_PATH) + " " + args, dir_);
  }

  // Scans 2 m apart with a gentle turn along the generated street.
  void MakeGeneratedDrive(int n) {
    const Points world = MakeSyntheticStreet(11);
    std::vector<Points> scans;
    std::vector<Transform> poses;
    for (int i = 0; i < n; ++i) {
      poses.push_back(PoseFromYawTranslation(0.04 * i, {-5.0 + 2.0 * i, 0.3 * i, 1.8}));
      scans.push_back(SimulateScan(world, poses.back(), 30.0, 0.02, 100 + i));
    }
    MakeDrive(scans, poses);
  }

  // The first n scans of the shared KITTI sequence, with its poses; false
  // when the data is absent.
  bool MakeKittiDrive(int n) {
    const fs::path kitti = fs::path(BOICP_SHARED_DATA_DIR) / "kitti00";
    if (!fs::is_directory(kitti)) return false;
    ScanFolderOptions options;
    options.count = n;
    const ScanFolder folder = ReadScanFolder(kitti.string(), options);
    std::vector<Points> scans;
    std::vector<Transform> poses;
    for (size_t i = 0; i < folder.scans.size(); ++i) {
      scans.push_back(LoadPointCloud(folder.scans[i].path, folder.scans[i].load).points);
      poses.push_back(folder.reference_poses[i].value());
    }
    messages_.clear();
    fs::remove_all(folder_);
    MakeDrive(scans, poses);
    return true;
  }

  // The drive as a folder of PCD scans, and as messages: the scans as the
  // folder loads them at 10 Hz and odometry (the poses, interpolated) at 20 Hz.
  void MakeDrive(const std::vector<Points>& scans, const std::vector<Transform>& poses) {
    const int n = static_cast<int>(scans.size());
    folder_ = dir_ / "scans";
    fs::create_directories(folder_);
    for (int i = 0; i < n; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "scan%03d.pcd", i);
      std::ofstream(folder_ / name, std::ios::binary)
          << EncodeBinaryPcd(scans[static_cast<size_t>(i)]);
      messages_.push_back({"/points",
                           "sensor_msgs/PointCloud2",
                           kFirstStamp + i * kScanPeriod,
                           LoadPointCloud((folder_ / name).string()).points,
                           Transform::Identity(),
                           {}});
    }
    for (int k = 0; k <= 2 * (n - 1); ++k) {
      const Transform& a = poses[static_cast<size_t>(k / 2)];
      const Transform& b = poses[static_cast<size_t>(std::min(k / 2 + 1, n - 1))];
      Transform pose = a;
      if (k % 2 == 1) {
        pose.topRightCorner<3, 1>() = 0.5 * (a.topRightCorner<3, 1>() + b.topRightCorner<3, 1>());
        const Eigen::Quaterniond qa(a.topLeftCorner<3, 3>()), qb(b.topLeftCorner<3, 3>());
        pose.topLeftCorner<3, 3>() = qa.slerp(0.5, qb).toRotationMatrix();
      }
      messages_.push_back(
          {"/odom", "nav_msgs/Odometry", kFirstStamp + k * kOdometryPeriod, {}, pose, {}});
    }
    std::stable_sort(
        messages_.begin(), messages_.end(),
        [](const DriveMessage& x, const DriveMessage& y) { return x.stamp_ns < y.stamp_ns; });
  }

  std::vector<uint8_t> Encode(const DriveMessage& m, MessageEncoding encoding,
                              const test::PointCloud2Options& options) const {
    if (m.topic == "/points") {
      return test::EncodePointCloud2(m.points, m.stamp_ns, "velodyne", encoding, options);
    }
    if (m.topic == "/tf_static") return test::EncodeTfMessage(m.transforms, m.stamp_ns, encoding);
    return test::EncodeOdometry(m.pose, m.stamp_ns, "odom", encoding);
  }

  // Logged 2 ms after their stamps, as a recorder does.
  fs::path WriteRos1Bag(test::Ros1BagCompression compression) {
    std::vector<test::Ros1BagMessage> out;
    for (const DriveMessage& m : messages_) {
      out.push_back({m.topic, m.type, m.stamp_ns + 2000000, Encode(m, MessageEncoding::kRos1, {})});
    }
    const fs::path bag = dir_ / "drive.bag";
    test::WriteRos1Bag(bag.string(), out, compression);
    return bag;
  }

  test::BagTestContents Ros2Contents(const test::PointCloud2Options& options) const {
    test::BagTestContents contents;
    contents.topics = {{"/odom", "nav_msgs/msg/Odometry"},
                       {"/points", "sensor_msgs/msg/PointCloud2"}};
    if (messages_.front().topic == "/tf_static") {
      contents.topics.push_back({"/tf_static", "tf2_msgs/msg/TFMessage"});
    }
    for (const DriveMessage& m : messages_) {
      contents.messages.push_back(
          {m.topic, m.stamp_ns + 2000000, Encode(m, MessageEncoding::kCdr, options)});
    }
    return contents;
  }

  // The drive as a ROS 2 .db3 folder split in two files, as rosbag2 splits
  // a bag by size.
  fs::path WriteSplitRos2Bag() const {
    test::BagTestContents first = Ros2Contents({}), second = first;
    const size_t half = first.messages.size() / 2;
    first.messages.resize(half);
    second.messages.erase(second.messages.begin(), second.messages.begin() + half);
    const fs::path folder = test::WriteRos2SqliteBag(dir_ / "drive_split", first).parent_path();
    fs::rename(test::WriteRos2SqliteBag(dir_ / "split_part", second), folder / "drive_split_1.db3");
    return folder;
  }

  // `boicp map` on a ROS 1 bag (lz4 chunks), a ROS 2 .db3 folder (float64
  // points), one split in two files and a ROS 2 .mcap file (zstd chunks) of
  // the drive gives the trajectory of the folder of its scans, byte for byte.
  void ExpectEveryBagGivesTheFoldersTrajectory();

  fs::path dir_;
  fs::path folder_;  // the drive's scans as PCD files
  std::vector<DriveMessage> messages_;
};

void BagCli::ExpectEveryBagGivesTheFoldersTrajectory() {
  const size_t n = static_cast<size_t>(
      std::count_if(messages_.begin(), messages_.end(),
                    [](const DriveMessage& m) { return m.topic == "/points"; }));
  const RunResult reference =
      Run("map " + folder_.string() + " -o " + (dir_ / "out-folder").string() + Quick());
  ASSERT_EQ(reference.exit_code, 0) << reference.err;
  const std::string trajectory = Slurp(dir_ / "out-folder" / "trajectory.kitti");

  test::PointCloud2Options float64;
  float64.float64 = true;
  test::McapWriteOptions zstd;
  zstd.compression = test::McapCompression::kZstd;
  const std::vector<std::pair<std::string, fs::path>> bags = {
      {"ros1-lz4", WriteRos1Bag(test::Ros1BagCompression::kLz4)},
      {"ros2-db3-folder",
       test::WriteRos2SqliteBag(dir_ / "drive_db3", Ros2Contents(float64)).parent_path()},
      {"ros2-db3-split", WriteSplitRos2Bag()},
      {"ros2-mcap-zstd", dir_ / "drive.mcap"},
  };
  test::WriteMcap(dir_ / "drive.mcap", Ros2Contents({}), zstd);
  const ScanFolder reference_scans = ReadScanFolder(folder_.string());
  for (const auto& [name, bag] : bags) {
    SCOPED_TRACE(name);
    const ScanFolder scans = ReadScanFolder(bag.string());
    ASSERT_EQ(scans.scans.size(), reference_scans.scans.size());
    for (size_t i = 0; i < scans.scans.size(); ++i) {
      const ScanSource& scan = scans.scans[i];
      const ScanSource& expected = reference_scans.scans[i];
      ASSERT_EQ(LoadPointCloud(scan.path, scan.load).points,
                LoadPointCloud(expected.path, expected.load).points);
    }
    const fs::path out = dir_ / ("out-" + name);
    const RunResult r = Run("map " + bag.string() + " -o " + out.string() + Quick());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string count = std::to_string(n);
    EXPECT_THAT(r.err, HasSubstr("bag, " + count + " of " + count + " scans")) << r.err;
    EXPECT_EQ(Slurp(out / "trajectory.kitti"), trajectory);
    // The header stamps are the trajectory's timestamps.
    const std::vector<TimedPose> tum = ReadTumTrajectory((out / "trajectory.tum").string());
    ASSERT_EQ(tum.size(), n);
    EXPECT_NEAR(tum[3].timestamp, 1.7e9 + 0.3, 1e-6);
  }
}

TEST_F(BagCli, EveryKindOfBagGivesTheFoldersTrajectory) {
  ExpectEveryBagGivesTheFoldersTrajectory();
}

TEST_F(BagCli, EveryKindOfBagOfRealKittiScansGivesTheFoldersTrajectory) {
  if (!MakeKittiDrive(4)) GTEST_SKIP() << "no ../shared/data/kitti00";
  ExpectEveryBagGivesTheFoldersTrajectory();
}

TEST_F(BagCli, OdometryGivesPriorsThatThePriorRungAnswers) {
  const fs::path bag = dir_ / "drive.mcap";
  test::WriteMcap(bag, Ros2Contents({}));
  const fs::path out = dir_ / "out";
  const RunResult r =
      Run("map " + bag.string() + " --odometry-topic /odom -o " + out.string() + Quick());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("/odom gives priors to 5 of them"));
  const json pairs = json::parse(Slurp(out / "pairs.json"));
  int by_prior = 0;
  for (const json& pair : pairs) by_prior += pair["answered_by"] == "prior";
  EXPECT_GE(by_prior, 1) << pairs.dump(1);
  EXPECT_THAT(r.err, HasSubstr(std::to_string(by_prior) + " prior"));
}

// The odometry tracks base_link; the LiDAR sits on it a quarter turn round
// and 1.2 m ahead, two /tf_static hops away. The priors are where the LiDAR
// was, in either serialization.
TEST_F(BagCli, TfStaticCarriesTheBodysOdometryToTheSensor) {
  const Transform mount = PoseFromYawTranslation(0.3, {1.2, 0.0, 0.5});
  const Transform lidar = PoseFromYawTranslation(M_PI / 2, {0.0, 0.1, 0.2});
  const Transform base_velodyne = mount * lidar;
  std::vector<Transform> sensor_poses;  // at the scans' stamps
  for (DriveMessage& m : messages_) {
    if (m.topic != "/odom") continue;
    if ((m.stamp_ns - kFirstStamp) % kScanPeriod == 0) sensor_poses.push_back(m.pose);
    m.pose = m.pose * base_velodyne.inverse();
  }
  BagScanSelection odometry;
  odometry.odometry_topic = "/odom";
  ScanFolderOptions options;
  options.bag = odometry;
  const auto read = [&](const fs::path& bag) { return ReadScanFolder(bag.string(), options); };

  const fs::path body_only = dir_ / "body.mcap";
  test::WriteMcap(body_only, Ros2Contents({}));
  const ScanFolder untold = read(body_only);
  EXPECT_THAT(untold.description, HasSubstr("no /tf_static path from base_link to velodyne"));
  ASSERT_EQ(untold.reference_poses.size(), sensor_poses.size());
  EXPECT_FALSE(untold.reference_poses[2]->isApprox(sensor_poses[2], 1e-3));

  messages_.insert(messages_.begin(),
                   DriveMessage{"/tf_static",
                                "tf2_msgs/TFMessage",
                                kFirstStamp,
                                {},
                                Transform::Identity(),
                                {{"/base_link", "mount", mount}, {"mount", "velodyne", lidar}}});
  const fs::path mcap = dir_ / "mounted.mcap";
  test::WriteMcap(mcap, Ros2Contents({}));
  for (const fs::path& bag : {mcap, WriteRos1Bag(test::Ros1BagCompression::kNone)}) {
    SCOPED_TRACE(bag.filename().string());
    const ScanFolder told = read(bag);
    EXPECT_THAT(told.description, HasSubstr("velodyne on base_link from /tf_static"));
    ASSERT_EQ(told.reference_poses.size(), sensor_poses.size());
    for (size_t i = 0; i < sensor_poses.size(); ++i) {
      ASSERT_TRUE(told.reference_poses[i]);
      EXPECT_TRUE(told.reference_poses[i]->isApprox(sensor_poses[i], 1e-9)) << i;
    }
  }
}

TEST_F(BagCli, WindowEveryAndMinIntervalPickTheScans) {
  const fs::path bag = dir_ / "drive.mcap";
  test::WriteMcap(bag, Ros2Contents({}));
  const auto stamps = [&](BagScanSelection selection, int stride) {
    ScanFolderOptions options;
    options.bag = selection;
    options.stride = stride;
    std::vector<double> out;
    for (const ScanSource& scan : ReadScanFolder(bag.string(), options).scans) {
      out.push_back(*scan.timestamp - 1.7e9);
    }
    return out;
  };
  using ::testing::DoubleNear;
  using ::testing::ElementsAre;
  BagScanSelection window;
  window.start = 0.1;
  window.duration = 0.25;
  EXPECT_THAT(stamps(window, 1),
              ElementsAre(DoubleNear(0.1, 1e-6), DoubleNear(0.2, 1e-6), DoubleNear(0.3, 1e-6)));
  BagScanSelection thinned;
  thinned.min_interval = 0.15;
  EXPECT_THAT(stamps(thinned, 1),
              ElementsAre(DoubleNear(0.0, 1e-6), DoubleNear(0.2, 1e-6), DoubleNear(0.4, 1e-6)));
  EXPECT_THAT(stamps({}, 4), ElementsAre(DoubleNear(0.0, 1e-6), DoubleNear(0.4, 1e-6)));

  const RunResult both = Run("map " + bag.string() + " --every 2 --min-interval 0.2 -o out");
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_THAT(both.err, HasSubstr("--every and --min-interval"));
}

TEST_F(BagCli, InfoListsTopicsTypesCountsAndDuration) {
  const fs::path bag = WriteRos1Bag(test::Ros1BagCompression::kNone);
  const RunResult text = Run("info " + bag.string());
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_THAT(text.out, HasSubstr("ROS 1 bag"));
  EXPECT_THAT(text.out, HasSubstr("/points"));
  const RunResult r = Run("info " + bag.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json info = json::parse(r.out);
  EXPECT_NEAR(info["duration"].get<double>(), 0.4, 1e-6);
  ASSERT_EQ(info["topics"].size(), 2u);
  EXPECT_EQ(info["topics"][0]["name"], "/odom");
  EXPECT_EQ(info["topics"][0]["messages"], 9);
  EXPECT_EQ(info["topics"][1]["type"], "sensor_msgs/PointCloud2");
  EXPECT_EQ(info["topics"][1]["messages"], 5);
}

// One "boicp map: error: FILE: problem" line and exit code 2, no map.
void ExpectOneErrorLine(const RunResult& r, const std::string& names) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("boicp map: error: "));
  EXPECT_THAT(r.err, HasSubstr(names));
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST_F(BagCli, BadBagsAndTopicsGiveOneErrorLine) {
  const fs::path mcap = dir_ / "drive.mcap";
  test::WriteMcap(mcap, Ros2Contents({}));
  const std::string bytes = Slurp(mcap);
  const fs::path cut = dir_ / "cut.mcap";
  test::WriteBytes(cut, bytes.substr(0, bytes.size() * 2 / 3));
  ExpectOneErrorLine(Run("map " + cut.string() + " -o out"), cut.string());

  const fs::path ros1 = WriteRos1Bag(test::Ros1BagCompression::kBz2);
  const std::string ros1_bytes = Slurp(ros1);
  const fs::path cut1 = dir_ / "cut.bag";
  test::WriteBytes(cut1, ros1_bytes.substr(0, ros1_bytes.size() / 2));
  ExpectOneErrorLine(Run("map " + cut1.string() + " -o out"), cut1.string());

  const fs::path not_sqlite = dir_ / "junk.db3";
  test::WriteBytes(not_sqlite, std::string(4096, 'x'));
  ExpectOneErrorLine(Run("map " + not_sqlite.string() + " -o out"), not_sqlite.string());

  ExpectOneErrorLine(Run("map " + mcap.string() + " --topic /odom -o out"),
                     "topic /odom holds nav_msgs/msg/Odometry, not PointCloud2");
  ExpectOneErrorLine(Run("map " + mcap.string() + " --odometry-topic /points -o out"),
                     "/points holds sensor_msgs/msg/PointCloud2");
  ExpectOneErrorLine(Run("map " + mcap.string() + " --start 60 -o out"), "inside the window");
  ExpectOneErrorLine(Run("map " + folder_.string() + " --topic /points -o out"), "need a bag");

  // Two PointCloud2 topics and no --topic: the candidates with their counts.
  test::BagTestContents two = Ros2Contents({});
  two.topics.push_back({"/points_raw", "sensor_msgs/msg/PointCloud2"});
  two.messages.push_back({"/points_raw", kFirstStamp, two.messages.back().data});
  const fs::path twice = dir_ / "two.mcap";
  test::WriteMcap(twice, two);
  const RunResult r = Run("map " + twice.string() + " -o out");
  ExpectOneErrorLine(r, "2 PointCloud2 topics, choose one with --topic");
  EXPECT_THAT(r.err, HasSubstr("/points (sensor_msgs/msg/PointCloud2, 5 messages)"));
  EXPECT_THAT(r.err, HasSubstr("/points_raw (sensor_msgs/msg/PointCloud2, 1 messages)"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "map.bt"));
}

#ifdef BOICP_TEST_WITH_DAEMON
// The client reads the bag and uploads each scan as a PCD; the daemon's
// trajectory is the local map's.
TEST_F(BagCli, SubmitUploadsTheBagsScans) {
  const fs::path bag = dir_ / "drive.mcap";
  test::WriteMcap(bag, Ros2Contents({}));
  const RunResult local = Run("map " + bag.string() + " -o " + (dir_ / "out").string() + Quick());
  ASSERT_EQ(local.exit_code, 0) << local.err;

  test::DaemonProcess daemon({"--data-dir", (dir_ / "daemon").string(), "--workers", "1"},
                             (dir_ / "daemon.log").string());
  const RunResult submitted = Run("submit " + bag.string() + " --server " + daemon.address() +
                                  " --config A --random-samples 4 --iterations 4 "
                                  "--rotation-bounds 0.2,0.2,3.14159 --resolution 0.3 --seed 5 "
                                  "--wait");
  ASSERT_EQ(submitted.exit_code, 0) << submitted.err << daemon.Log();
  EXPECT_THAT(submitted.err, HasSubstr("uploaded 5 scans"));
  const std::string job = submitted.out.substr(0, submitted.out.find('\n'));
  const RunResult exported = Run("export " + job + " --server " + daemon.address() + " -o " +
                                 (dir_ / "daemon.kitti").string());
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_EQ(Slurp(dir_ / "daemon.kitti"), Slurp(dir_ / "out" / "trajectory.kitti"));
}
#endif

}  // namespace
}  // namespace boicp
