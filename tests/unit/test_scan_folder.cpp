// Scan folders: every layout on small folders generated in a temp dir, every
// malformed-input error, selection, and (when ../shared/data is present) the
// real KITTI and 7-Scenes folders.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/input_error.hpp"
#include "boicp/io/scan_folder.hpp"

#ifndef BOICP_SHARED_DATA_DIR
#define BOICP_SHARED_DATA_DIR ""
#endif

namespace boicp {
namespace {
using boicp::test::InputErrorMessage;

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

void WriteText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

void WriteBin(const fs::path& path, int points) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  for (int i = 0; i < points; ++i) {
    const float p[4] = {1.0f + static_cast<float>(i), 2.0f, 0.5f, 0.0f};
    out.write(reinterpret_cast<const char*>(p), sizeof(p));
  }
}

std::string Row12(const Transform& T) {
  std::string line;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) line += std::to_string(T(i, j)) + " ";
  }
  return line + "\n";
}

class ScanFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() /
            ("boicp_scan_folder_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  // A KITTI folder of `n` scans; Tr is a yaw of 0.3 rad plus an offset.
  fs::path MakeKitti(int n, bool with_side_files = true) {
    const fs::path dir = root_ / "kitti";
    for (int i = n - 1; i >= 0; --i) {  // created out of order on purpose
      char name[32];
      std::snprintf(name, sizeof(name), "%06d.bin", i);
      WriteBin(dir / "velodyne" / name, 5);
    }
    if (!with_side_files) return dir;
    WriteText(dir / "calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: " + Row12(Tr()));
    std::string poses, times;
    for (int i = 0; i < n; ++i) {
      poses += Row12(CameraPose(i));
      times += std::to_string(0.1 * i) + "\n";
    }
    WriteText(dir / "poses.txt", poses);
    WriteText(dir / "times.txt", times);
    return dir;
  }
  static Transform Tr() {
    Transform T = Transform::Identity();
    T.block<3, 3>(0, 0) = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.block<3, 1>(0, 3) = Eigen::Vector3d(0.1, -0.2, 0.3);
    return T;
  }
  static Transform CameraPose(int i) {
    Transform P = Transform::Identity();
    P(2, 3) = 0.5 * i;  // forward along the camera's z
    return P;
  }

  fs::path MakeSevenScenes(int n, bool subfolders) {
    const fs::path dir = root_ / "scene";
    const fs::path depth = subfolders ? dir / "depth" : dir;
    const fs::path pose = subfolders ? dir / "pose" : dir;
    for (int i = 0; i < n; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "frame-%06d", i);
      WriteText(depth / (std::string(name) + ".depth.png"), "not loaded here");
      WriteText(pose / (std::string(name) + ".pose.txt"),
                "1 0 0 " + std::to_string(i) + "\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
    }
    WriteText(dir / "camera-intrinsics.txt", "585 0 320\n0 585 240\n0 0 1\n");
    return dir;
  }

  fs::path MakeTum(const std::string& name) {
    const fs::path dir = root_ / name;
    WriteText(dir / "depth.txt",
              "# depth maps\n# file: 'x.bag'\n# timestamp filename\n"
              "1305031102.160407 depth/1305031102.160407.png\n"
              "1305031102.194330 depth/1305031102.194330.png\n");
    WriteText(dir / "depth/1305031102.160407.png", "x");
    WriteText(dir / "depth/1305031102.194330.png", "x");
    return dir;
  }

  fs::path root_;
};

TEST_F(ScanFolderTest, ParsesLayoutNames) {
  EXPECT_EQ(ParseScanLayout("auto"), ScanLayout::kAuto);
  EXPECT_EQ(ParseScanLayout("KITTI"), ScanLayout::kKitti);
  EXPECT_EQ(ParseScanLayout("tum"), ScanLayout::kTum);
  EXPECT_EQ(ParseScanLayout("7scenes"), ScanLayout::kSevenScenes);
  EXPECT_EQ(ParseScanLayout("files"), ScanLayout::kCloudFiles);
  EXPECT_EQ(ScanLayoutName(ScanLayout::kSevenScenes), "7scenes");
  EXPECT_THAT(InputErrorMessage([] { ParseScanLayout("lidar"); }), HasSubstr("'lidar'"));
}

TEST_F(ScanFolderTest, KittiScansInNameOrderWithVelodynePosesAndTimes) {
  const fs::path dir = MakeKitti(3);
  const ScanFolder folder = ReadScanFolder(dir.string());
  EXPECT_EQ(folder.layout, ScanLayout::kKitti);
  ASSERT_EQ(folder.scans.size(), 3u);
  ASSERT_EQ(folder.reference_poses.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const ScanSource& scan = folder.scans[static_cast<size_t>(i)];
    EXPECT_EQ(fs::path(scan.path).filename().string(), "00000" + std::to_string(i) + ".bin");
    EXPECT_EQ(scan.load.format, CloudFormat::kKittiBin);
    ASSERT_TRUE(scan.timestamp.has_value());
    EXPECT_NEAR(*scan.timestamp, 0.1 * i, 1e-9);
    EXPECT_FALSE(scan.prior_pose.has_value()) << "poses are priors only when asked";
    // The velodyne pose relative to the first velodyne frame: Tr^-1 P_i Tr.
    const Transform expected = Tr().inverse() * CameraPose(i) * Tr();
    ASSERT_TRUE(folder.reference_poses[static_cast<size_t>(i)].has_value());
    EXPECT_TRUE(folder.reference_poses[static_cast<size_t>(i)]->isApprox(expected, 1e-5));
  }
  EXPECT_THAT(folder.description, HasSubstr("KITTI"));

  ScanFolderOptions priors;
  priors.poses_as_priors = true;
  const ScanFolder with_priors = ReadScanFolder(dir.string(), priors);
  ASSERT_TRUE(with_priors.scans[2].prior_pose.has_value());
  EXPECT_TRUE(with_priors.scans[2].prior_pose->isApprox(*folder.reference_poses[2], 1e-12));
}

TEST_F(ScanFolderTest, KittiWithoutSideFilesHasNoPoses) {
  const ScanFolder folder = ReadScanFolder(MakeKitti(2, false).string());
  ASSERT_EQ(folder.scans.size(), 2u);
  EXPECT_FALSE(folder.reference_poses[0].has_value());
  EXPECT_FALSE(folder.scans[0].timestamp.has_value());
}

TEST_F(ScanFolderTest, KittiMalformedSideFilesNameTheFile) {
  const fs::path dir = MakeKitti(3);
  WriteText(dir / "poses.txt", Row12(CameraPose(0)) + "1 2 3\n" + Row12(CameraPose(2)));
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("poses.txt: data line 2 has 3 numbers"));

  WriteText(dir / "poses.txt", Row12(CameraPose(0)));
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("poses.txt: 1 lines for 3 scans"));

  WriteText(dir / "poses.txt",
            Row12(CameraPose(0)) + Row12(CameraPose(1)) + "1 x 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("poses.txt:3: 'x' is not a finite number"));

  WriteText(dir / "poses.txt", Row12(CameraPose(0)) + Row12(CameraPose(1)) + Row12(CameraPose(2)));
  WriteText(dir / "calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("calib.txt: no 'Tr:' line"));

  fs::remove(dir / "calib.txt");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("calib.txt: missing"));

  fs::remove(dir / "poses.txt");
  WriteText(dir / "times.txt", "0.0\n0.1\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("times.txt: 2 lines for 3 scans"));
}

TEST_F(ScanFolderTest, SelectsFirstStrideCount) {
  const fs::path dir = MakeKitti(10);
  ScanFolderOptions options;
  options.first = 1;
  options.stride = 3;
  const ScanFolder every_third = ReadScanFolder(dir.string(), options);
  ASSERT_EQ(every_third.scans.size(), 3u);  // 1, 4, 7
  EXPECT_EQ(fs::path(every_third.scans[2].path).filename().string(), "000007.bin");
  EXPECT_NEAR(*every_third.scans[1].timestamp, 0.4, 1e-9);
  EXPECT_TRUE(
      every_third.reference_poses[1]->isApprox(Tr().inverse() * CameraPose(4) * Tr(), 1e-5));
  EXPECT_THAT(every_third.description, HasSubstr("3 of 10"));

  options.count = 2;
  EXPECT_EQ(ReadScanFolder(dir.string(), options).scans.size(), 2u);

  options.first = 10;
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string(), options); }),
              HasSubstr("first: 10 is beyond the 10 scans"));
  options.first = 0;
  options.stride = 0;
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string(), options); }),
              HasSubstr("stride"));
  options.stride = 1;
  options.count = -1;
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string(), options); }),
              HasSubstr("count"));
}

TEST_F(ScanFolderTest, TumCameraFromFolderNameAndTimestamps) {
  const fs::path dir = MakeTum("rgbd_dataset_freiburg2_desk");
  const ScanFolder folder = ReadScanFolder(dir.string());
  EXPECT_EQ(folder.layout, ScanLayout::kTum);
  ASSERT_EQ(folder.scans.size(), 2u);
  const ScanSource& scan = folder.scans[1];
  EXPECT_EQ(scan.load.format, CloudFormat::kDepthPng);
  EXPECT_DOUBLE_EQ(scan.load.depth.depth_scale, 5000.0);
  ASSERT_TRUE(scan.load.depth.intrinsics.has_value());
  EXPECT_DOUBLE_EQ(scan.load.depth.intrinsics->fx, 520.9);
  EXPECT_DOUBLE_EQ(scan.load.depth.intrinsics->cy, 249.7);
  EXPECT_NEAR(*scan.timestamp, 1305031102.194330, 1e-6);
  EXPECT_EQ(fs::path(scan.path).filename().string(), "1305031102.194330.png");
  EXPECT_FALSE(folder.reference_poses[0].has_value());

  // groundtruth.txt: the pose nearest in time, within 20 ms.
  WriteText(dir / "groundtruth.txt",
            "# timestamp tx ty tz qx qy qz qw\n"
            "1305031102.1500 1 2 3 0 0 0 1\n"
            "1305031102.1700 4 5 6 0 0 0 1\n"
            "1305031102.2500 7 8 9 0 0 0 1\n");
  const ScanFolder with_truth = ReadScanFolder(dir.string());
  ASSERT_TRUE(with_truth.reference_poses[0].has_value());
  EXPECT_DOUBLE_EQ((*with_truth.reference_poses[0])(0, 3), 4.0);
  EXPECT_FALSE(with_truth.reference_poses[1].has_value()) << "nearest is 56 ms away";
  WriteText(dir / "groundtruth.txt", "1305031102.1500 1 2 3\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("groundtruth.txt"));
}

TEST_F(ScanFolderTest, TumNeedsACamera) {
  const fs::path dir = MakeTum("my_recording");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("names no camera"));
  ScanFolderOptions options;
  options.tum_camera = "fr1";
  options.depth_scale = 1000.0;
  const ScanFolder fr1 = ReadScanFolder(dir.string(), options);
  EXPECT_DOUBLE_EQ(fr1.scans[0].load.depth.intrinsics->fx, 517.3);
  EXPECT_DOUBLE_EQ(fr1.scans[0].load.depth.depth_scale, 1000.0);
  options.tum_camera = "fr3";
  EXPECT_DOUBLE_EQ(ReadScanFolder(dir.string(), options).scans[0].load.depth.intrinsics->fy, 539.2);
  options.tum_camera = "fr9";
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string(), options); }),
              HasSubstr("'fr9' is not fr1, fr2 or fr3"));
  options.tum_camera.clear();
  options.intrinsics = Intrinsics{500, 501, 320, 240};
  EXPECT_DOUBLE_EQ(ReadScanFolder(dir.string(), options).scans[0].load.depth.intrinsics->fy, 501);
}

TEST_F(ScanFolderTest, TumMalformedListNamesTheLine) {
  const fs::path dir = MakeTum("rgbd_dataset_freiburg1_xyz");
  WriteText(dir / "depth.txt", "# c\n1.0 depth/missing.png\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }), HasSubstr("depth.txt:2: "));
  WriteText(dir / "depth.txt", "1.0\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("depth.txt:1: expected 'timestamp filename'"));
  WriteText(dir / "depth.txt", "# nothing\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("lists no depth images"));
}

TEST_F(ScanFolderTest, SevenScenesInSubfoldersAndFlat) {
  for (bool subfolders : {true, false}) {
    fs::remove_all(root_ / "scene");
    const fs::path dir = MakeSevenScenes(4, subfolders);
    const ScanFolder folder = ReadScanFolder(dir.string());
    EXPECT_EQ(folder.layout, ScanLayout::kSevenScenes);
    ASSERT_EQ(folder.scans.size(), 4u);
    EXPECT_DOUBLE_EQ(folder.scans[3].load.depth.depth_scale, 1000.0);
    EXPECT_DOUBLE_EQ(folder.scans[3].load.depth.intrinsics->fx, 585.0);
    ASSERT_TRUE(folder.reference_poses[3].has_value());
    EXPECT_DOUBLE_EQ((*folder.reference_poses[3])(0, 3), 3.0);
    EXPECT_EQ(fs::path(folder.scans[3].path).filename().string(), "frame-000003.depth.png");
  }
}

TEST_F(ScanFolderTest, SevenScenesMissingPiecesNameTheFile) {
  const fs::path dir = MakeSevenScenes(3, true);
  fs::remove(dir / "pose" / "frame-000001.pose.txt");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("frame-000001.pose.txt: no such file"));
  WriteText(dir / "pose" / "frame-000001.pose.txt", "1 2 3\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("frame-000001.pose.txt"));
  fs::remove(dir / "camera-intrinsics.txt");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(dir.string()); }),
              HasSubstr("camera-intrinsics.txt: no such file"));
}

TEST_F(ScanFolderTest, CloudFilesInNameOrderAndMixedFormatsRefused) {
  WriteText(root_ / "b.xyz", "1 2 3\n");
  WriteText(root_ / "a.xyz", "1 2 3\n");
  WriteText(root_ / "README.txt", "side files are ignored");
  const ScanFolder folder = ReadScanFolder(root_.string());
  EXPECT_EQ(folder.layout, ScanLayout::kCloudFiles);
  ASSERT_EQ(folder.scans.size(), 2u);
  EXPECT_EQ(fs::path(folder.scans[0].path).filename().string(), "a.xyz");
  EXPECT_EQ(folder.scans[0].load.format, CloudFormat::kXyz);

  WriteText(root_ / "c.ply", "ply\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(root_.string()); }),
              HasSubstr("mixes point formats (.ply, .xyz)"));
}

TEST_F(ScanFolderTest, AListOfFilesKeepsItsOrderAndFormatsAndSelects) {
  WriteText(root_ / "b.xyz", "1 2 3\n");
  WriteBin(root_ / "a.bin", 5);
  WriteText(root_ / "c.xyz", "1 2 3\n");
  const std::vector<std::string> files = {(root_ / "b.xyz").string(), (root_ / "a.bin").string(),
                                          (root_ / "c.xyz").string()};
  const ScanFolder listed = ReadScanList(files);
  EXPECT_EQ(listed.layout, ScanLayout::kCloudFiles);
  ASSERT_EQ(listed.scans.size(), 3u);
  EXPECT_EQ(listed.scans[0].path, files[0]);
  EXPECT_EQ(listed.scans[1].load.format, CloudFormat::kKittiBin);
  EXPECT_EQ(listed.scans[2].load.format, CloudFormat::kXyz);
  EXPECT_EQ(listed.reference_poses.size(), 3u);
  EXPECT_THAT(listed.description, HasSubstr("3 of 3 scans (*.bin, *.xyz)"));

  ScanFolderOptions every_other;
  every_other.stride = 2;
  const ScanFolder selected = ReadScanList(files, every_other);
  ASSERT_EQ(selected.scans.size(), 2u);
  EXPECT_EQ(selected.scans[1].path, files[2]);
}

TEST_F(ScanFolderTest, AListNamesItsMissingFileAndADepthImageWithoutItsCamera) {
  WriteText(root_ / "a.xyz", "1 2 3\n");
  WriteText(root_ / "d.png", "not read here");
  const std::string present = (root_ / "a.xyz").string();
  EXPECT_THAT(InputErrorMessage([&] {
                ReadScanList({present, (root_ / "gone.xyz").string()});
              }),
              HasSubstr("gone.xyz: no such file"));
  EXPECT_THAT(InputErrorMessage([&] {
                ReadScanList({present, (root_ / "d.png").string()});
              }),
              HasSubstr("d.png: a depth image needs the intrinsics and the depth scale"));
  EXPECT_THAT(InputErrorMessage([&] { ReadScanList({}); }), HasSubstr("empty"));

  ScanFolderOptions camera;
  camera.intrinsics = Intrinsics{500.0, 500.0, 320.0, 240.0};
  camera.depth_scale = 1000.0;
  const ScanFolder depth = ReadScanList({(root_ / "d.png").string()}, camera);
  EXPECT_EQ(depth.scans[0].load.format, CloudFormat::kDepthPng);
  EXPECT_EQ(depth.scans[0].load.depth.depth_scale, 1000.0);
}

TEST_F(ScanFolderTest, MissingOrUnrecognisableFolders) {
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder((root_ / "none").string()); }),
              HasSubstr("none: no such folder"));
  WriteText(root_ / "notes.md", "x");
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(root_.string()); }),
              HasSubstr("no scans found"));
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder((root_ / "notes.md").string()); }),
              HasSubstr("is not a folder"));
  ScanFolderOptions kitti;
  kitti.layout = ScanLayout::kKitti;
  EXPECT_THAT(InputErrorMessage([&] { ReadScanFolder(root_.string(), kitti); }),
              HasSubstr("velodyne: no .bin scans"));
}

TEST_F(ScanFolderTest, CheckScansLoadNamesTheFirstBadScanWhateverTheThreads) {
  const fs::path dir = MakeKitti(4, false);
  EXPECT_NO_THROW(CheckScansLoad(ReadScanFolder(dir.string()).scans, 2));
  WriteText(dir / "velodyne" / "000001.bin", "12345");  // not a multiple of 16 bytes
  WriteText(dir / "velodyne" / "000003.bin", "123");
  for (const int threads : {1, 4}) {
    const std::string message =
        InputErrorMessage([&] { CheckScansLoad(ReadScanFolder(dir.string()).scans, threads); });
    EXPECT_THAT(message, HasSubstr("000001.bin")) << threads << " threads";
    EXPECT_THAT(message, Not(HasSubstr("000003.bin"))) << threads << " threads";
  }
}

TEST(ScanFolderRealData, KittiAndSevenScenes) {
  const fs::path data = BOICP_SHARED_DATA_DIR;
  if (data.empty() || !fs::is_directory(data / "kitti00") ||
      !fs::is_directory(data / "7scenes_redkitchen")) {
    GTEST_SKIP() << "shared data not found at '" << data.string() << "'";
  }
  const ScanFolder kitti = ReadScanFolder((data / "kitti00").string());
  EXPECT_EQ(kitti.layout, ScanLayout::kKitti);
  ASSERT_EQ(kitti.scans.size(), 10u);
  // PROVENANCE.txt: T_velo_0<-1 translation (0.858768, 0.046516, 0.022240) m.
  const Transform T01 = kitti.reference_poses[0]->inverse() * *kitti.reference_poses[1];
  EXPECT_NEAR(T01(0, 3), 0.858768, 1e-4);
  EXPECT_NEAR(T01(1, 3), 0.046516, 1e-4);
  EXPECT_NEAR(T01(2, 3), 0.022240, 1e-4);

  ScanFolderOptions options;
  options.stride = 30;
  options.count = 4;
  const ScanFolder scenes = ReadScanFolder((data / "7scenes_redkitchen").string(), options);
  EXPECT_EQ(scenes.layout, ScanLayout::kSevenScenes);
  ASSERT_EQ(scenes.scans.size(), 4u);
  EXPECT_EQ(fs::path(scenes.scans[3].path).filename().string(), "frame-000090.depth.png");
  EXPECT_TRUE(scenes.reference_poses[3].has_value());
  EXPECT_NO_THROW(CheckScansLoad(scenes.scans, 2));
}

}  // namespace
}  // namespace boicp
