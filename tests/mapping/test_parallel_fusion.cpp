// Fusion on several threads writes the same bytes as on one, and both match
// OctoMap's own discretised insertion, which the map used before.

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "../support/files_and_processes.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/map_assembly.hpp"

namespace boicp {
namespace {
using boicp::test::Slurp;

namespace fs = std::filesystem;

class ParallelFusion : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_fusion_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

octomap::Pointcloud InMapFrame(const Points& points, const Transform& T_map_scan) {
  octomap::Pointcloud cloud;
  for (const Point& p : points) {
    const Point q = T_map_scan.topLeftCorner<3, 3>() * p + T_map_scan.topRightCorner<3, 1>();
    cloud.push_back(static_cast<float>(q.x()), static_cast<float>(q.y()),
                    static_cast<float>(q.z()));
  }
  return cloud;
}

// OctoMap's own insertion of the drive, as OccupancyMap did it before it ray
// cast scans itself.
void WriteReferenceMaps(const std::vector<SyntheticScan>& drive, const OccupancySettings& s,
                        const std::string& ot_path, const std::string& bt_path) {
  octomap::OcTree tree(s.resolution);
  tree.setProbHit(s.prob_hit);
  tree.setProbMiss(s.prob_miss);
  tree.setClampingThresMin(s.clamp_min);
  tree.setClampingThresMax(s.clamp_max);
  for (const SyntheticScan& scan : drive) {
    const Point origin = scan.T_world_scan.topRightCorner<3, 1>();
    tree.insertPointCloud(
        InMapFrame(scan.points, scan.T_world_scan),
        octomap::point3d(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                         static_cast<float>(origin.z())),
        s.max_range > 0.0 ? s.max_range : -1.0, /*lazy_eval=*/true,
        /*discretize=*/true);
  }
  tree.updateInnerOccupancy();
  std::ofstream ot(ot_path, std::ios::binary);
  ASSERT_TRUE(tree.write(ot));
  ot.close();
  std::ofstream bt(bt_path, std::ios::binary);
  ASSERT_TRUE(tree.writeBinary(bt));
}

TEST_F(ParallelFusion, InsertScanMatchesOctoMapsDiscretisedInsertion) {
  const std::vector<SyntheticScan> drive = MakeSyntheticDrive(4, 21);
  for (const double max_range : {0.0, 12.0}) {  // 12 m cuts many rays short
    SCOPED_TRACE(max_range);
    OccupancySettings settings;
    settings.resolution = 0.3;
    settings.max_range = max_range;
    OccupancyMap map(settings);
    for (const SyntheticScan& scan : drive) {
      map.InsertScan(scan.points, scan.T_world_scan, Point::Zero());
    }
    map.WriteFull(Path("ours.ot"));
    map.WriteBinary(Path("ours.bt"));
    WriteReferenceMaps(drive, settings, Path("octomap.ot"), Path("octomap.bt"));
    EXPECT_GT(fs::file_size(Path("ours.bt")), 1000u);
    EXPECT_TRUE(Slurp(Path("ours.ot")) == Slurp(Path("octomap.ot")));
    EXPECT_TRUE(Slurp(Path("ours.bt")) == Slurp(Path("octomap.bt")));
  }
}

TEST_F(ParallelFusion, UpdateCellsDoNotDependOnTheThreadCount) {
  const SyntheticDrive drive(1, 4);
  const SyntheticScan scan = drive.Scan(0);
  OccupancySettings settings;
  settings.resolution = 0.4;
  const OccupancyMap map(settings);
  const ScanUpdate serial = map.ComputeUpdate(scan.points, scan.T_world_scan, Point::Zero(), 1);
  EXPECT_GT(serial.FreeCells(), 1000u);
  EXPECT_GT(serial.OccupiedCells(), 1000u);
  for (const int threads : {2, 3, 8}) {
    const ScanUpdate parallel =
        map.ComputeUpdate(scan.points, scan.T_world_scan, Point::Zero(), threads);
    EXPECT_EQ(parallel.FreeCells(), serial.FreeCells()) << threads;
    EXPECT_EQ(parallel.OccupiedCells(), serial.OccupiedCells()) << threads;
  }
}

TEST_F(ParallelFusion, FuseScansWritesTheSameBytesOnAnyThreadCount) {
  const SyntheticDrive drive(10, 9);
  std::vector<ScanSource> scans;
  std::vector<Transform> poses;
  for (int i = 0; i < drive.size(); ++i) {
    const SyntheticScan scan = drive.Scan(i);
    ScanSource source;
    source.path = Path("scan" + std::to_string(i) + ".xyz");
    WriteXyz(source.path, scan.points);
    scans.push_back(source);
    poses.push_back(scan.T_world_scan);
  }
  const auto fuse = [&](int threads) {
    const std::string dir = Path("threads" + std::to_string(threads));
    fs::create_directories(dir);
    MapBuildSettings settings;
    settings.occupancy.resolution = 0.3;
    settings.occupancy.max_range = 25.0;
    settings.fusion_threads = threads;
    const MapOutputPaths out{dir + "/map.bt", dir + "/map.ot", "", "", dir + "/map.ply"};
    FuseScans(scans, poses, settings, out);
    return out;
  };
  const MapOutputPaths serial = fuse(1);
  EXPECT_GT(fs::file_size(serial.octomap_bt), 1000u);
  // 9 threads: windows of four scans, each ray cast on two threads.
  for (const int threads : {2, 3, 9}) {
    SCOPED_TRACE(threads);
    const MapOutputPaths parallel = fuse(threads);
    EXPECT_TRUE(Slurp(parallel.octomap_bt) == Slurp(serial.octomap_bt));
    EXPECT_TRUE(Slurp(parallel.octomap_ot) == Slurp(serial.octomap_ot));
    EXPECT_TRUE(Slurp(parallel.cloud_ply) == Slurp(serial.cloud_ply));
  }
}

}  // namespace
}  // namespace boicp
