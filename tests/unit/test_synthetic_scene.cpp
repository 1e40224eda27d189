// The generated drive: long drives see street all the way, a loop comes back
// to its start, and the same seed gives the same scans.

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

TEST(SyntheticDrive, StreetSegmentsDifferAndRepeat) {
  EXPECT_TRUE(SameBytes(MakeStreetSegment(5, 2), MakeStreetSegment(5, 2)));
  EXPECT_FALSE(SameBytes(MakeStreetSegment(5, 2), MakeStreetSegment(5, 3)));
  EXPECT_FALSE(SameBytes(MakeStreetSegment(5, 2), MakeStreetSegment(6, 2)));
}

}  // namespace
}  // namespace boicp
