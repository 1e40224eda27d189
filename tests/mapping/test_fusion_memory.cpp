// Fusion's memory: the estimate a map is refused by bounds the cells one
// scan's rays actually mark, from street scans at several leaf sizes and
// ray cuts to points strung along a few rays; and FuseScans stops, rather
// than grows, past its limit.

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/fusion_memory.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// The leaves one scan's rays mark, counted by ray casting it.
double CellsMarked(const Points& points, const Point& sensor_origin,
                   const OccupancySettings& settings) {
  const OccupancyMap map(settings);
  const ScanUpdate update = map.ComputeUpdate(points, Transform::Identity(), sensor_origin, 2);
  return static_cast<double>(update.FreeCells() + update.OccupiedCells());
}

Points StreetScan() {
  return SimulateScan(MakeSyntheticStreet(11, 20.0), PoseFromYawTranslation(0.3, {1.0, 0, 0}), 30.0,
                      0.01, 11);
}

// Points every 30 cm out to 60 m on `rays` rays from the origin: a line seen
// end on, which a bound counting every point as a ray would take for
// `rays` x 200 rays.
Points StarScan(int rays) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  Points points;
  for (int r = 0; r < rays; ++r) {
    const double z = 1.0 - 2.0 * (r + 0.5) / rays;
    const double radius = std::sqrt(1.0 - z * z);
    const Point direction(radius * std::cos(golden * r), radius * std::sin(golden * r), z);
    for (double d = 0.3; d <= 60.0; d += 0.3) points.push_back(d * direction);
  }
  return points;
}

struct BoundCase {
  double leaf;       // metres
  double max_range;  // metres, 0 = uncut
};

class RayCellsBoundCase : public ::testing::TestWithParam<BoundCase> {};

// An estimate that refused what fits would refuse real maps; one far above
// the cells would too. Both are checked: at least the cells marked, at most
// ten times as many (bench/fusion_memory.sh measures 1.9-3.5 times on real scans).
TEST_P(RayCellsBoundCase, CoversTheCellsAStreetScanMarksWithinTenTimes) {
  OccupancySettings settings;
  settings.resolution = GetParam().leaf;
  settings.max_range = GetParam().max_range;
  const Points points = StreetScan();
  const double marked = CellsMarked(points, Point::Zero(), settings);
  const double bound = RayCellsBound(ProfileRanges(points), 0.0, settings);
  EXPECT_GE(bound, marked);
  EXPECT_LE(bound, 10.0 * marked);
}

TEST_P(RayCellsBoundCase, CoversThemFromASensorOriginAwayFromTheFrameOrigin) {
  OccupancySettings settings;
  settings.resolution = GetParam().leaf;
  settings.max_range = GetParam().max_range;
  const Points points = StreetScan();
  const Point origin(3.0, -2.0, 1.5);
  EXPECT_GE(RayCellsBound(ProfileRanges(points), origin.norm(), settings),
            CellsMarked(points, origin, settings));
}

INSTANTIATE_TEST_SUITE_P(LeavesAndCuts, RayCellsBoundCase,
                         ::testing::Values(BoundCase{0.5, 0.0}, BoundCase{0.2, 0.0},
                                           BoundCase{0.1, 0.0}, BoundCase{0.05, 0.0},
                                           BoundCase{0.05, 10.0}, BoundCase{0.02, 8.0}));

TEST(RayCellsBound, CountsPointsAlongOneRayAsOneRay) {
  OccupancySettings settings;
  settings.resolution = 0.02;
  const Points points = StarScan(50);
  const double marked = CellsMarked(points, Point::Zero(), settings);
  const double bound = RayCellsBound(ProfileRanges(points), 0.0, settings);
  EXPECT_GE(bound, marked);
  EXPECT_LE(bound, 10.0 * marked);
}

TEST(RayCellsBound, GrowsAsLeavesShrinkAndIsZeroWithoutAProfile) {
  const RangeProfile profile = ProfileRanges(StreetScan());
  OccupancySettings coarse, fine;
  coarse.resolution = 0.2;
  fine.resolution = 0.05;
  EXPECT_GT(RayCellsBound(profile, 0.0, fine), RayCellsBound(profile, 0.0, coarse));
  EXPECT_EQ(RayCellsBound(RangeProfile{}, 0.0, fine), 0.0);
}

class FusionLimit : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_fusion_limit_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    ScanSource scan;
    scan.path = (dir_ / "scan.xyz").string();
    WriteXyz(scan.path, StreetScan());
    scans_ = {scan, scan};
    settings_.occupancy.resolution = 0.1;
    settings_.fusion_threads = 2;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<RangeProfile> Profiles() const { return ProfileScans(scans_, 2); }

  fs::path dir_;
  std::vector<ScanSource> scans_;
  MapBuildSettings settings_;
};

TEST_F(FusionLimit, RefusesAMapEstimatedOverItNamingTheEstimateAndTheFlag) {
  const double cells = RayCellsBound(Profiles()[0], 0.0, settings_.occupancy);
  const auto just_under = static_cast<size_t>(cells * kFusionBytesPerCell) - 1;
  try {
    RequireFusionWithinLimit(scans_, Profiles(), settings_.occupancy, just_under);
    FAIL() << "not refused";
  } catch (const LimitExceeded& e) {
    EXPECT_THAT(e.what(), HasSubstr("needs an estimated"));
    EXPECT_THAT(e.what(), HasSubstr("--max-fusion-mb"));
  }
  EXPECT_NO_THROW(
      RequireFusionWithinLimit(scans_, Profiles(), settings_.occupancy, just_under + 2));
  EXPECT_NO_THROW(RequireFusionWithinLimit(scans_, Profiles(), settings_.occupancy, 0));
  EXPECT_NO_THROW(
      RequireFusionWithinLimit(scans_, {RangeProfile{}, RangeProfile{}}, settings_.occupancy, 1));
}

// A map the estimate accepts fuses within the same limit: the estimate
// never lets through what FuseScans then stops.
TEST_F(FusionLimit, FuseScansStopsPastItAndWritesNothingButFusesWhatTheEstimateAccepts) {
  const std::vector<Transform> poses(2, Transform::Identity());
  MapOutputPaths outputs;
  outputs.octomap_bt = (dir_ / "map.bt").string();
  settings_.max_fusion_bytes = size_t{1} << 20;
  try {
    FuseScans(scans_, poses, settings_, outputs);
    FAIL() << "fusion went past its limit";
  } catch (const LimitExceeded& e) {
    EXPECT_THAT(e.what(), HasSubstr("limit of 1 MB (--max-fusion-mb)"));
  }
  EXPECT_FALSE(fs::exists(outputs.octomap_bt));

  settings_.max_fusion_bytes = static_cast<size_t>(
      std::ceil(RayCellsBound(Profiles()[0], 0.0, settings_.occupancy) * kFusionBytesPerCell));
  ASSERT_NO_THROW(RequireFusionWithinLimit(scans_, Profiles(), settings_.occupancy,
                                           settings_.max_fusion_bytes));
  EXPECT_NO_THROW(FuseScans(scans_, poses, settings_, outputs));
  EXPECT_TRUE(fs::exists(outputs.octomap_bt));
}

// At 1 cm leaves an OctoMap reaches 327.68 m from its origin along each
// axis; a point beyond would wrap to a key on the far side and mark a leaf
// that no scan saw.
TEST(OccupancyMap, PointsBeyondTheKeyRangeAreLeftOutAndCounted) {
  OccupancySettings settings;
  settings.resolution = 0.01;
  const Points near = {{1.0, 0.0, 0.0}, {1.0, 0.5, 0.0}, {0.0, 2.0, 0.5}};
  Points with_far = near;
  with_far.push_back({400.0, 0.0, 0.0});
  with_far.push_back({-1000.0, 5.0, 0.0});
  const auto fuse = [&](const Points& points, size_t* out_of_range) {
    OccupancyMap map(settings);
    const ScanUpdate update = map.ComputeUpdate(points, Transform::Identity(), Point::Zero(), 2);
    *out_of_range = update.PointsOutOfRange();
    map.ApplyUpdate(update);
    return map.OccupiedLeaves();
  };
  size_t dropped_near = 0, dropped_far = 0;
  const size_t leaves_near = fuse(near, &dropped_near);
  EXPECT_EQ(fuse(with_far, &dropped_far), leaves_near);
  EXPECT_EQ(dropped_near, 0u);
  EXPECT_EQ(dropped_far, 2u);
}

TEST(RangeProfile, CountsEveryPointOnceAndKeepsTheFarthest) {
  const Points points = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 3000}};
  const RangeProfile profile = ProfileRanges(points);
  ASSERT_EQ(profile.counts.size(), static_cast<size_t>(kRangeProfileBins));
  uint64_t total = 0, rays = 0;
  for (size_t bin = 0; bin < profile.counts.size(); ++bin) {
    total += profile.counts[bin];
    rays += profile.ray_counts[bin];
  }
  EXPECT_EQ(total, 4u);
  EXPECT_EQ(rays, 4u);
  EXPECT_DOUBLE_EQ(profile.max_range, 3000.0);
}

}  // namespace
}  // namespace boicp
