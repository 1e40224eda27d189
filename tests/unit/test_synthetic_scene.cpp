// The generated drive: long drives see street all the way, a loop comes back
// to its start, and the same seed gives the same scans.

#include <algorithm>
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "boicp/io/synthetic_scene.hpp"

namespace boicp {
namespace {

bool SameBytes(const Points& a, const Points& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Point)) == 0);
}

TEST(SyntheticDrive, AHundredScanDriveHasNoEmptyScan) {
  const SyntheticDrive drive(100, 7);
  ASSERT_EQ(drive.size(), 100);
  const size_t first_size = drive.Scan(0).points.size();
  for (int i = 0; i < drive.size(); ++i) {
    // Every scan sees about as much street as the first, not a thinning end.
    EXPECT_GT(drive.Scan(i).points.size(), first_size / 2) << "scan " << i;
  }
}

TEST(SyntheticDrive, LoopEndsBesideItsStart) {
  const SyntheticDrive drive(60, 7, /*loop=*/true);
  const Point start = drive.Pose(0).topRightCorner<3, 1>();
  const Point end = drive.Pose(59).topRightCorner<3, 1>();
  const Point middle = drive.Pose(30).topRightCorner<3, 1>();
  EXPECT_LT((end - start).norm(), 4.0);
  EXPECT_GT((middle - start).norm(), 50.0);
  EXPECT_GT(drive.Scan(59).points.size(), 1000u);
}

TEST(SyntheticDrive, SameSeedSameScansAndLongerDrivesExtendShorterOnes) {
  const SyntheticDrive a(50, 3), b(50, 3), longer(80, 3), other(50, 4);
  for (const int i : {0, 20, 49}) {
    EXPECT_TRUE(SameBytes(a.Scan(i).points, b.Scan(i).points)) << i;
    EXPECT_TRUE(SameBytes(a.Scan(i).points, longer.Scan(i).points)) << i;
    EXPECT_EQ(a.Pose(i), longer.Pose(i));
  }
  EXPECT_FALSE(SameBytes(a.Scan(45).points, other.Scan(45).points));
}

// A sweep moving 1 m along x: the point straight ahead is measured halfway
// (0.5 m on), the one straight behind at the end, the one to the right a
// quarter in; a sweep that stands still measures them as SimulateScan does.
TEST(SyntheticDrive, ASweptScanSeesEachPointFromWhereTheSensorIsThen) {
  const Points world = {Point(10, 0, 0), Point(-10, 1e-9, 0), Point(0, -10, 0)};
  const Transform start = PoseFromYawTranslation(0.0, {0, 0, 0});
  const Points swept = SimulateSweptScan(world, start, {1, 0, 0}, 0.0, 35.0, 0.0, 1);
  ASSERT_EQ(swept.size(), 3u);
  EXPECT_TRUE(swept[0].isApprox(Point(9.5, 0, 0), 1e-9)) << swept[0].transpose();
  EXPECT_NEAR(swept[1].x(), -11.0, 1e-6);
  EXPECT_TRUE(swept[2].isApprox(Point(-0.25, -10, 0), 1e-9)) << swept[2].transpose();
  EXPECT_TRUE(SameBytes(SimulateSweptScan(world, start, {0, 0, 0}, 0.0, 35.0, 0.0, 1),
                        SimulateScan(world, start, 35.0, 0.0, 1)));
}

// --drift: steps and turns vary as a throttled log's do, the loop still ends
// beside its start, and the same seed gives the same drive.
TEST(SyntheticDrive, ADriftingDriveIsIrregularAndReturns) {
  const SyntheticDrive drive(200, 7, /*loop=*/true, /*drift=*/true);
  double shortest = 1e9, longest = 0.0, sharpest = 0.0;
  for (int i = 1; i < 100; ++i) {
    const Transform step = drive.Pose(i - 1).inverse() * drive.Pose(i);
    shortest = std::min(shortest, step.topRightCorner<3, 1>().head<2>().norm());
    longest = std::max(longest, step.topRightCorner<3, 1>().head<2>().norm());
    sharpest = std::max(sharpest, std::abs(std::atan2(step(1, 0), step(0, 0))));
  }
  EXPECT_LT(shortest, 1.0);
  EXPECT_GT(longest, 4.0);
  EXPECT_GT(sharpest, 0.35);
  const Point start = drive.Pose(0).topRightCorner<3, 1>();
  EXPECT_LT((drive.Pose(199).topRightCorner<3, 1>() - start).norm(), 4.0);
  EXPECT_GT(drive.Scan(199).points.size(), 1000u);
  const SyntheticDrive again(200, 7, true, true), still(200, 7, true, false);
  EXPECT_TRUE(SameBytes(drive.Scan(150).points, again.Scan(150).points));
  EXPECT_FALSE(drive.Pose(50).isApprox(still.Pose(50)));
}

TEST(SyntheticDrive, StreetSegmentsDifferAndRepeat) {
  EXPECT_TRUE(SameBytes(MakeStreetSegment(5, 2), MakeStreetSegment(5, 2)));
  EXPECT_FALSE(SameBytes(MakeStreetSegment(5, 2), MakeStreetSegment(5, 3)));
  EXPECT_FALSE(SameBytes(MakeStreetSegment(5, 2), MakeStreetSegment(6, 2)));
}

}  // namespace
}  // namespace boicp
