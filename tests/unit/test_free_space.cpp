// The free-space check: a scan's view from its sensor, and the share of
// another scan's points an alignment moves into space that view saw through.

#include <gtest/gtest.h>

#include <cmath>

#include "boicp/icp/free_space.hpp"
#include "boicp/io/synthetic_scene.hpp"

namespace boicp {
namespace {

// A 4 m cube's walls sampled every `step` metres, seen from its centre.
Points Room(double step = 0.05) {
  Points walls;
  const int samples = static_cast<int>(std::lround(4.0 / step));
  for (int i = 0; i <= samples; ++i) {
    for (int j = 0; j <= samples; ++j) {
      const double u = -2.0 + i * step, v = -2.0 + j * step;
      for (double side : {-2.0, 2.0}) {
        walls.emplace_back(side, u, v);
        walls.emplace_back(u, side, v);
        walls.emplace_back(u, v, side);
      }
    }
  }
  return walls;
}

TEST(RangeImage, HoldsTheNearestReturnInEachDirection) {
  const RangeImage view(Room(0.01), Point::Zero());
  EXPECT_EQ(view.covered_cells(), 6u * 128 * 128);  // every direction from inside a room
  EXPECT_NEAR(view.NearestReturn(Point(1.0, 0.0, 0.0)), 2.0, 0.01);
  EXPECT_NEAR(view.NearestReturn(Point(0.0, 0.0, -0.5)), 2.0, 0.01);
  // The corner's direction: the wall points in its cell are about 2 sqrt(3) m away.
  EXPECT_NEAR(view.NearestReturn(Point(1.0, 1.0, 1.0)), 2.0 * std::sqrt(3.0), 0.1);

  const RangeImage moved(Room(0.01), Point(1.0, 0.0, 0.0));
  EXPECT_NEAR(moved.NearestReturn(Point(2.0, 0.0, 0.0)), 1.0, 0.01);
  EXPECT_TRUE(std::isinf(
      RangeImage(Points{Point(5, 0, 0)}, Point::Zero()).NearestReturn(Point(-1.0, 0.0, 0.0))));
}

struct StreetScans {
  Points source, target;
  Transform truth;  // T_target_source
};

StreetScans TwoScansOfAStreet() {
  const Points world = MakeSyntheticStreet(11, 15.0);
  const Transform T_world_target = PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8});
  const Transform T_world_source = PoseFromYawTranslation(0.3, {1.5, 0.5, 1.8});
  return {SimulateScan(world, T_world_source, 30.0, 0.01, 1),
          SimulateScan(world, T_world_target, 30.0, 0.01, 2),
          T_world_target.inverse() * T_world_source};
}

TEST(SeenThroughShare, TheRightAlignmentSeesThroughNothingAndAWrongOneMuch) {
  const StreetScans scans = TwoScansOfAStreet();
  const NearestNeighborIndex target(scans.target);
  const RangeImage view(scans.target, Point::Zero());
  const auto share = [&](const Transform& T) {
    return SeenThroughShare(scans.source, target, view, T, 0.3, 0.2);
  };
  EXPECT_LT(share(scans.truth), 0.01);

  // Turned half round about the target's sensor: the street's sides swap.
  Transform half_turn = PoseFromYawTranslation(M_PI, Eigen::Vector3d::Zero());
  EXPECT_GT(share(half_turn * scans.truth), 0.1);
  // Moved 3 m toward one side of the street.
  Transform sideways = PoseFromYawTranslation(0.0, {0.0, 3.0, 0.0});
  EXPECT_GT(share(sideways * scans.truth), 0.1);
}

TEST(SeenThroughShare, PointsOnTheTargetsSurfacesOrBehindThemDoNotCount) {
  const Points room = Room();
  const NearestNeighborIndex target(room);
  const RangeImage view(room, Point::Zero());
  // The same walls, and points behind them, are not seen through.
  EXPECT_EQ(SeenThroughShare(room, target, view, Transform::Identity(), 0.1, 0.05), 0.0);
  Points behind;
  for (const Point& p : room) behind.push_back(1.5 * p);
  EXPECT_EQ(SeenThroughShare(behind, target, view, Transform::Identity(), 0.1, 0.05), 0.0);
  // A box of half the size inside the room is.
  Points inside;
  for (const Point& p : room) inside.push_back(0.5 * p);
  EXPECT_EQ(SeenThroughShare(inside, target, view, Transform::Identity(), 0.1, 0.05), 1.0);
  // Directions the target saw nothing in are not counted: seen from a view
  // of the +x wall alone, the inner box's -x face is not seen through.
  Points east_wall, west_face;
  for (const Point& p : room) {
    if (p.x() == 2.0) east_wall.push_back(p);
    if (p.x() == -2.0) west_face.push_back(0.5 * p);
  }
  const RangeImage east_view(east_wall, Point::Zero());
  EXPECT_EQ(SeenThroughShare(west_face, target, east_view, Transform::Identity(), 0.1, 0.05), 0.0);
  Points east_face;
  for (const Point& p : east_wall) east_face.push_back(0.5 * p);
  EXPECT_EQ(SeenThroughShare(east_face, target, east_view, Transform::Identity(), 0.1, 0.05), 1.0);
}

}  // namespace
}  // namespace boicp
