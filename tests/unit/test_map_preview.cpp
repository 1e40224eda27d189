// Map previews: rendering (colour by height, colour bar, trajectory marks),
// PNG output through Open3D, and reading occupied cells from .bt / .ot files.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <open3d/geometry/Image.h>
#include <open3d/io/ImageIO.h>
#include <Eigen/Geometry>

#include "../support/files_and_processes.hpp"
#include "boicp/mapping/map_preview.hpp"
#include "boicp/mapping/occupancy_map.hpp"

namespace boicp {
namespace {
using boicp::test::HasStagingFile;

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::array<int, 3> PixelAt(const RgbImage& image, int x, int y) {
  const size_t i =
      (static_cast<size_t>(y) * static_cast<size_t>(image.width) + static_cast<size_t>(x)) * 3;
  return {image.pixels[i], image.pixels[i + 1], image.pixels[i + 2]};
}

// A 10 m x 5 m floor at z = 0 with a 3 m wall along its north edge.
OccupiedCells FloorAndWall() {
  OccupiedCells cells;
  cells.resolution = 0.25;
  for (double x = 0.125; x < 10; x += 0.25) {
    for (double y = 0.125; y < 5; y += 0.25) {
      cells.centres.emplace_back(x, y, 0.0);
      cells.sizes.push_back(0.25);
    }
    for (double z = 0.125; z < 3; z += 0.25) {
      cells.centres.emplace_back(x, 4.875, z);
      cells.sizes.push_back(0.25);
    }
  }
  return cells;
}

TEST(MapPreview, ColoursByHeightWithTrajectoryMarks) {
  PreviewOptions options;
  options.size_px = 400;
  const Points trajectory = {{1, 1, 0}, {5, 2, 0}, {9, 1, 0}};
  const RgbImage image = RenderTopDown(FloorAndWall(), trajectory, options);
  EXPECT_GT(image.width, image.height) << "the map is wider than tall";
  EXPECT_LE(std::max(image.width, image.height), 400);
  ASSERT_EQ(image.pixels.size(), static_cast<size_t>(image.width * image.height * 3));

  std::set<std::array<int, 3>> colours;
  for (int y = 0; y < image.height; y += 3) {
    for (int x = 0; x < image.width; x += 3) colours.insert(PixelAt(image, x, y));
  }
  EXPECT_GT(colours.size(), 10u) << "not a blank or flat image";

  // Floor (low) is blue, the wall seen from above (high) red: compare the
  // first and last map pixels down a column without trajectory.
  const RgbImage plain = RenderTopDown(FloorAndWall(), {}, options);
  const int column = plain.width / 3;
  std::vector<std::array<int, 3>> down;
  for (int y = 0; y < plain.height; ++y) {
    const auto p = PixelAt(plain, column, y);
    if (p != std::array<int, 3>{24, 24, 28}) down.push_back(p);
  }
  ASSERT_GT(down.size(), 10u);
  EXPECT_GT(down.front()[0], down.front()[2]) << "the wall (top of the picture) is red";
  EXPECT_GT(down.back()[2], down.back()[0]) << "the floor is blue";

  // Green start mark and red end mark exist.
  bool green = false, red = false;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const auto p = PixelAt(image, x, y);
      green |= p == std::array<int, 3>{40, 220, 60};
      red |= p == std::array<int, 3>{235, 40, 40};
    }
  }
  EXPECT_TRUE(green);
  EXPECT_TRUE(red);
}

// The longer side is the size asked for, whatever the map's extent: its
// scale is that size over the extent, and extent times scale can round up.
TEST(MapPreview, TheLongerSideIsTheSizeAskedFor) {
  PreviewOptions options;
  options.size_px = 300;
  for (int k = 1; k <= 400; ++k) {
    const double length = 3.0 + 0.0731 * k;
    OccupiedCells cells;
    cells.resolution = 0.1;
    for (double x : {0.05, length - 0.05}) {
      cells.centres.emplace_back(x, 0.05, 0.0);
      cells.sizes.push_back(0.1);
    }
    cells.centres.emplace_back(1.0, 1.0, 0.5);
    cells.sizes.push_back(0.1);
    const RgbImage image = RenderTopDown(cells, {}, options);
    ASSERT_EQ(image.width, 300) << "map " << length << " m long";
  }
}

TEST(MapPreview, LooksDownAlongTheGivenUp) {
  // The floor-and-wall room as a depth camera's frame holds it: the room's
  // up (z) becomes +y there, its y becomes -z.
  const Eigen::Matrix3d camera =
      Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  OccupiedCells tilted = FloorAndWall();
  for (Point& c : tilted.centres) c = camera * c;
  PreviewOptions options;
  options.size_px = 400;
  const RgbImage room = RenderTopDown(FloorAndWall(), {}, options);
  const RgbImage side_on = RenderTopDown(tilted, {}, options);
  options.up = camera * Eigen::Vector3d::UnitZ();
  const RgbImage from_above = RenderTopDown(tilted, {}, options);

  auto differing = [](const RgbImage& a, const RgbImage& b) {
    if (a.width != b.width || a.height != b.height) return 1.0;
    size_t count = 0;
    for (size_t i = 0; i < a.pixels.size(); i += 3) count += a.pixels[i] != b.pixels[i];
    return static_cast<double>(count) / static_cast<double>(a.pixels.size() / 3);
  };
  EXPECT_LT(differing(from_above, room), 0.01) << "the same floor plan as the upright room";
  EXPECT_GT(differing(side_on, room), 0.1) << "seen along z it is a side view";
  options.up = Eigen::Vector3d::Zero();
  EXPECT_THROW(RenderTopDown(tilted, {}, options), InputError);
}

TEST(MapPreview, RefusesNothingToDrawAndTinySizes) {
  EXPECT_THROW(RenderTopDown(OccupiedCells{}, {}), InputError);
  PreviewOptions tiny;
  tiny.size_px = 10;
  EXPECT_THROW(RenderTopDown(FloorAndWall(), {}, tiny), InputError);
}

TEST(MapPreview, WritesAPngOpen3dReadsBack) {
  const fs::path dir = fs::temp_directory_path() / ("boicp_preview_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  PreviewOptions options;
  options.size_px = 256;
  const RgbImage image = RenderTopDown(FloorAndWall(), {}, options);
  WritePng((dir / "p.png").string(), image);
  open3d::geometry::Image read;
  ASSERT_TRUE(open3d::io::ReadImage((dir / "p.png").string(), read));
  EXPECT_EQ(read.width_, image.width);
  EXPECT_EQ(read.height_, image.height);
  EXPECT_EQ(read.num_of_channels_, 3);
  EXPECT_TRUE(std::equal(image.pixels.begin(), image.pixels.end(), read.data_.begin()));
  EXPECT_FALSE(HasStagingFile(dir));
  fs::remove_all(dir);
}

TEST(MapPreview, ReadsOccupiedCellsOfBtAndOt) {
  const fs::path dir =
      fs::temp_directory_path() / ("boicp_preview_bt_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  OccupancySettings settings;
  settings.resolution = 0.5;
  OccupancyMap map(settings);
  Points wall;
  for (double y = -2; y <= 2; y += 0.1) {
    for (double z = 0; z <= 1; z += 0.1) wall.emplace_back(4.0, y, z);
  }
  map.InsertScan(wall, Transform::Identity(), Point::Zero());
  map.WriteFull((dir / "m.ot").string());
  map.WriteBinary((dir / "m.bt").string());
  for (const char* name : {"m.bt", "m.ot"}) {
    // OctoMap's own readers print "Reading ... octree type"; ours stays quiet.
    ::testing::internal::CaptureStderr();
    ::testing::internal::CaptureStdout();
    const OccupiedCells cells = ReadOccupiedCells((dir / name).string());
    EXPECT_EQ(::testing::internal::GetCapturedStdout(), "") << name;
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << name;
    EXPECT_DOUBLE_EQ(cells.resolution, 0.5) << name;
    ASSERT_FALSE(cells.centres.empty()) << name;
    for (const Point& c : cells.centres) EXPECT_NEAR(c.x(), 4.0, 0.5) << name;
  }
  std::ofstream(dir / "bad.bt") << "hello\n";
  try {
    ReadOccupiedCells((dir / "bad.bt").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bad.bt: not an OctoMap file"));
  }
  EXPECT_THROW(ReadOccupiedCells((dir / "none.bt").string()), InputError);
  // A tree cut short after its header is an error, not an empty map.
  std::string bytes;
  {
    std::ifstream in(dir / "m.bt", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::ofstream(dir / "cut.bt", std::ios::binary) << bytes.substr(0, bytes.find("data\n") + 7);
  EXPECT_THROW(ReadOccupiedCells((dir / "cut.bt").string()), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace boicp
