// Map outputs (core): trajectory files, the merged voxel cloud, OctoMap
// fusion and FuseScans as a whole.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "../support/files_and_processes.hpp"
#include "boicp/icp/voxel_cloud.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/io/trajectory_io.hpp"
#include "boicp/mapping/map_assembly.hpp"

namespace boicp {
namespace {
using boicp::test::HasStagingFile;

namespace fs = std::filesystem;

class MapOutputs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_map_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::vector<Transform> SomePoses() {
  return {PoseFromYawTranslation(0.0, {0, 0, 0}), PoseFromYawTranslation(0.3, {1.5, -0.2, 0.1}),
          PoseFromYawTranslation(-2.5, {3.0, 0.4, 0.2})};
}

TEST_F(MapOutputs, TumAndKittiTrajectoriesRoundTrip) {
  const auto poses = SomePoses();
  {
    std::ofstream tum(Path("t.tum")), kitti(Path("t.kitti"));
    WriteTumTrajectory(tum, {0.5, 1.0, 1.5}, poses);
    WriteKittiTrajectory(kitti, poses);
  }
  const auto tum = ReadTumTrajectory(Path("t.tum"));
  const auto kitti = ReadKittiTrajectory(Path("t.kitti"));
  ASSERT_EQ(tum.size(), 3u);
  ASSERT_EQ(kitti.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_LT((tum[i].pose - poses[i]).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((kitti[i] - poses[i]).cwiseAbs().maxCoeff(), 1e-9);
  }
  EXPECT_DOUBLE_EQ(tum[2].timestamp, 1.5);
  std::ostringstream bad;
  EXPECT_THROW(WriteTumTrajectory(bad, {0.0}, poses), InputError);
}

TEST_F(MapOutputs, VoxelAccumulatorKeepsOneCentroidPerVoxel) {
  VoxelAccumulator grid(1.0);
  grid.Add({{0.1, 0.1, 0.1}, {0.3, 0.5, 0.9}, {1.5, 0.5, 0.5}});
  grid.Add({{0.2, 0.2, 0.2}}, PoseFromYawTranslation(0.0, {1.0, 0.0, 0.0}));
  const Points centroids = grid.Centroids();
  ASSERT_EQ(centroids.size(), 2u);
  EXPECT_TRUE(centroids[0].isApprox(Point(0.2, 0.3, 0.5)));
  EXPECT_TRUE(centroids[1].isApprox(Point(1.35, 0.35, 0.35)));
  EXPECT_THROW(VoxelAccumulator(0.0), InputError);
}

// 1e300 m over 1 mm voxels has no int64 index (the cast would be undefined,
// a UBSan report in the sanitizer stage): the point is left out.
TEST_F(MapOutputs, VoxelAccumulatorLeavesOutPointsBeyondItsIndexRange) {
  VoxelAccumulator grid(0.001);
  grid.Add({{0.1, 0.1, 0.1}, {1e300, 0.0, 0.0}, {0.0, -1e19, 0.0}});
  ASSERT_EQ(grid.Centroids().size(), 1u);
  EXPECT_TRUE(grid.Centroids()[0].isApprox(Point(0.1, 0.1, 0.1)));
}

TEST_F(MapOutputs, OccupancySettingsAreValidated) {
  OccupancySettings s;
  s.resolution = 0.0;
  EXPECT_THROW(ValidateOccupancySettings(s), InputError);
  s = {};
  s.prob_hit = 0.4;
  EXPECT_THROW(ValidateOccupancySettings(s), InputError);
  s = {};
  s.clamp_min = 0.99;
  EXPECT_THROW(ValidateOccupancySettings(s), InputError);
}

TEST_F(MapOutputs, FuseScansWritesEveryOutputAndMarksScannedSurfaces) {
  const Points world = MakeSyntheticStreet(11, 10.0);
  std::vector<ScanSource> scans;
  const auto poses = SomePoses();
  for (size_t i = 0; i < poses.size(); ++i) {
    const std::string path = Path("scan" + std::to_string(i) + ".xyz");
    WriteXyz(path, SimulateScan(world, poses[i], 20.0, 0.0, i));
    ScanSource scan;
    scan.path = path;
    scans.push_back(scan);
  }
  MapBuildSettings settings;
  settings.occupancy.resolution = 0.25;
  settings.occupancy.max_range = 20.0;
  MapOutputPaths out{Path("map.bt"), Path("map.ot"), Path("t.tum"), Path("t.kitti"),
                     Path("map.ply")};
  // OctoMap's own .bt writer prints " done."; fusion stays quiet.
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  const FusionSummary summary = FuseScans(scans, poses, settings, out);
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_GT(summary.occupied_leaves, 1000u);
  EXPECT_GT(summary.cloud_points, 1000u);
  for (const std::string& file :
       {out.octomap_bt, out.octomap_ot, out.trajectory_tum, out.trajectory_kitti, out.cloud_ply}) {
    EXPECT_TRUE(fs::is_regular_file(file)) << file;
    EXPECT_FALSE(HasStagingFile(fs::path(file).parent_path())) << file;
  }
  std::ifstream bt(out.octomap_bt);
  std::string first_line;
  std::getline(bt, first_line);
  EXPECT_EQ(first_line, "# Octomap OcTree binary file");

  // The scans' own points, in the map frame, fall in occupied cells.
  octomap::OcTree tree(out.octomap_bt);
  const Points scan = SimulateScan(world, poses[1], 15.0, 0.0, 99);
  int occupied = 0, checked = 0;
  for (size_t i = 0; i < scan.size(); i += 20, ++checked) {
    const Point p = (poses[1] * scan[i].homogeneous()).head<3>();
    const octomap::OcTreeNode* node = tree.search(p.x(), p.y(), p.z());
    if (node && tree.isNodeOccupied(node)) ++occupied;
  }
  EXPECT_GT(occupied, 0.9 * checked);

  std::unique_ptr<octomap::AbstractOcTree> full(octomap::AbstractOcTree::read(out.octomap_ot));
  ASSERT_TRUE(full);
  auto* full_tree = dynamic_cast<octomap::OcTree*>(full.get());
  ASSERT_NE(full_tree, nullptr);
  // The .bt holds the bytes OctoMap's own writer gives for the same tree.
  std::ostringstream octomap_bt;
  ASSERT_TRUE(full_tree->writeBinary(octomap_bt));
  std::ifstream written(out.octomap_bt, std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(written), {}), octomap_bt.str());
}

TEST_F(MapOutputs, FuseScansStopsWhenAsked) {
  ScanSource scan;
  scan.path = Path("one.xyz");
  WriteXyz(scan.path, {{1, 0, 0}, {0, 1, 0}});
  MapOutputPaths out;
  out.octomap_bt = Path("map.bt");
  AssemblyCallbacks callbacks;
  callbacks.stop_requested = [] { return true; };
  EXPECT_THROW(
      FuseScans({scan, scan}, {Transform::Identity(), Transform::Identity()}, {}, out, callbacks),
      Cancelled);
  EXPECT_FALSE(fs::exists(out.octomap_bt));
}

TEST_F(MapOutputs, EstimatePosesAnchorsOnTheFirstPrior) {
  std::vector<ScanSource> scans(2);
  scans[0].prior_pose = PoseFromYawTranslation(1.0, {5, 5, 0});
  const Transform T10 = PoseFromYawTranslation(0.1, {-1, 0, 0});
  const PoseEstimate estimate = EstimatePoses(scans, {{{0, 1}, T10}}, {});
  EXPECT_FALSE(estimate.optimised);
  EXPECT_TRUE(estimate.poses[0].isApprox(*scans[0].prior_pose));
  EXPECT_TRUE(estimate.poses[1].isApprox(*scans[0].prior_pose * T10.inverse()));
}

// Two drives that nothing joins: each in its own first scan's frame. A
// scan its own drive does not reach is still an error.
TEST_F(MapOutputs, EstimatePosesPlacesEachDriveApartInItsOwnFrame) {
  std::vector<ScanSource> scans(4);
  const Transform T10 = PoseFromYawTranslation(0.1, {-1, 0, 0});
  const Transform T32 = PoseFromYawTranslation(-0.2, {0, 2, 0});
  const PoseEstimate estimate = EstimatePoses(scans, {{{0, 1}, T10}, {{3, 2}, T32}}, {}, {2});
  ASSERT_EQ(estimate.poses.size(), 4u);
  EXPECT_TRUE(estimate.poses[1].isApprox(T10.inverse()));
  EXPECT_TRUE(estimate.poses[2].isApprox(Transform::Identity()));
  EXPECT_TRUE(estimate.poses[3].isApprox(T32));
  EXPECT_EQ(estimate.kept, std::vector<bool>({true, true}));

  EXPECT_THROW(EstimatePoses(scans, {{{0, 1}, T10}, {{3, 2}, T32}}, {}), InputError) << "one drive";
  EXPECT_THROW(EstimatePoses(scans, {{{0, 1}, T10}}, {}, {2}), InputError) << "scan 3 unreached";
}

}  // namespace
}  // namespace boicp
