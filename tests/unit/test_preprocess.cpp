// Preprocessing: the voxel downsample gives Open3D's points bit for bit, in
// the order the cloud first reaches their cells or in Open3D's own (the fixed
// budget's answers depend on that order through the seeded subsamples); the
// crop keeps the range it names.

#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>

#include "boicp/icp/preprocess.hpp"
#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/synthetic_scene.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;

Points Open3dDownsample(const Points& points, double voxel) {
  return open3d::geometry::PointCloud(points).VoxelDownSample(voxel)->points_;
}

Points Sorted(Points points) {
  std::sort(points.begin(), points.end(), [](const Point& a, const Point& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  return points;
}

// Bit for bit: EXPECT_EQ on doubles compares exactly.
void ExpectSamePoints(const Points& ours, const Points& open3d, double voxel) {
  ASSERT_EQ(ours.size(), open3d.size()) << "voxel " << voxel;
  for (size_t i = 0; i < ours.size(); ++i) {
    ASSERT_EQ(ours[i].x(), open3d[i].x()) << "point " << i << ", voxel " << voxel;
    ASSERT_EQ(ours[i].y(), open3d[i].y()) << "point " << i << ", voxel " << voxel;
    ASSERT_EQ(ours[i].z(), open3d[i].z()) << "point " << i << ", voxel " << voxel;
  }
}

// Open3D's points in either order, and in Open3D's order when asked.
void ExpectSameAsOpen3d(const Points& points, double voxel) {
  const Points open3d = Open3dDownsample(points, voxel);
  ExpectSamePoints(Sorted(VoxelDownsample(points, voxel)), Sorted(open3d), voxel);
  ExpectSamePoints(VoxelDownsample(points, voxel, CellOrder::kOpen3d), open3d, voxel);
}

TEST(VoxelDownsample, SameAsOpen3dOnAStreet) {
  const Points street = MakeSyntheticStreet(3, 20.0);
  for (const double voxel : {0.05, 0.3, 1.7}) ExpectSameAsOpen3d(street, voxel);
}

TEST(VoxelDownsample, SameAsOpen3dOnRealScans) {
  const fs::path root(BOICP_SHARED_DATA_DIR);
  const fs::path kitti = root / "kitti00" / "velodyne" / "000000.bin";
  const fs::path depth = root / "7scenes_redkitchen" / "depth" / "frame-000100.depth.png";
  if (!fs::exists(kitti) || !fs::exists(depth)) {
    GTEST_SKIP() << "real data folder '" << root.string()
                 << "' (BOICP_SHARED_DATA_DIR, ../shared/data) is absent";
  }
  ExpectSameAsOpen3d(LoadPointCloud(kitti.string()).points, 0.1);
  LoadOptions options;
  options.depth.intrinsics = Intrinsics{585.0, 585.0, 320.0, 240.0};
  options.depth.depth_scale = 1000.0;
  const Points room = LoadPointCloud(depth.string(), options).points;
  for (const double voxel : {0.0064, 0.04}) ExpectSameAsOpen3d(room, voxel);
}

TEST(VoxelDownsample, OnePointPerOccupiedVoxelAtTheCentroid) {
  const Points points = {{0.1, 0.1, 0.1}, {0.3, 0.3, 0.3}, {5.0, 5.0, 5.0}};
  const Points sampled = VoxelDownsample(points, 1.0);
  ASSERT_EQ(sampled.size(), 2u);
  EXPECT_TRUE(sampled[0].isApprox(Point(0.2, 0.2, 0.2)));
  EXPECT_TRUE(sampled[1].isApprox(Point(5.0, 5.0, 5.0)));
}

TEST(VoxelDownsample, CellsComeInTheOrderTheCloudFirstReachesThem) {
  Points points;
  for (int i = 0; i < 5000; ++i) {
    const double x = static_cast<double>((i * 7919) % 5000);  // every cell once, shuffled
    points.push_back({x, 0.0, 0.0});
    points.push_back({x + 0.25, 0.0, 0.0});
  }
  const Points sampled = VoxelDownsample(points, 1.0);
  ASSERT_EQ(sampled.size(), 5000u);
  for (size_t i = 0; i < sampled.size(); ++i) {
    ASSERT_EQ(sampled[i].x(), points[2 * i].x() + 0.125) << "cell " << i;
  }
}

TEST(VoxelDownsample, NonPositiveVoxelOrEmptyCloudIsUnchanged) {
  const Points points = {{1.0, 2.0, 3.0}, {1.0, 2.0, 3.001}};
  EXPECT_EQ(VoxelDownsample(points, 0.0).size(), 2u);
  EXPECT_EQ(VoxelDownsample(points, -1.0).size(), 2u);
  EXPECT_TRUE(VoxelDownsample({}, 0.1).empty());
}

TEST(VoxelDownsample, VoxelTooSmallForTheCloudIsAnInputError) {
  const Points points = {{0.0, 0.0, 0.0}, {1e6, 0.0, 0.0}};
  EXPECT_THROW(VoxelDownsample(points, 1e-6), InputError);
}

TEST(CropByRange, KeepsTheClosedRangeAndNoUpperLimitAtZero) {
  const Points points = {{0.5, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 2.0}, {3.0, 0.0, 0.0}};
  EXPECT_EQ(CropByRange(points, 1.0, 2.0).size(), 2u);
  EXPECT_EQ(CropByRange(points, 1.0, 0.0).size(), 3u);
  EXPECT_EQ(CropByRange(points, 0.0, 0.0).size(), 4u);
}

}  // namespace
}  // namespace boicp
