// The transform between two frames of a tf tree: composed through a common
// root, whatever the path, or nothing when there is no path.
#include "boicp/io/frame_tree.hpp"

#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "boicp/registration/search_space.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

Transform Pose(double roll, double pitch, double yaw, const Eigen::Vector3d& t) {
  Transform T = Transform::Identity();
  T.topLeftCorner<3, 3>() = RotationFromEuler(roll, pitch, yaw);
  T.topRightCorner<3, 1>() = t;
  return T;
}

// base_link -> mount -> velodyne, and base_link -> imu.
std::vector<FrameTransform> Robot() {
  return {{"base_link", "mount", Pose(0, 0, 0.3, {1.2, 0.0, 0.5})},
          {"mount", "velodyne", Pose(0.02, -0.1, M_PI / 2, {0.0, 0.1, 0.2})},
          {"/base_link", "/imu", Pose(0, 0, 0, {-0.3, 0.0, 0.1})}};
}

TEST(FrameTree, ComposesThroughTheCommonRootBothWays) {
  const std::vector<FrameTransform> tree = Robot();
  const Transform base_velodyne = tree[0].parent_child * tree[1].parent_child;
  const std::optional<Transform> down = TransformBetween(tree, "base_link", "velodyne");
  ASSERT_TRUE(down);
  EXPECT_TRUE(down->isApprox(base_velodyne, 1e-12));
  const std::optional<Transform> up = TransformBetween(tree, "/velodyne", "base_link");
  ASSERT_TRUE(up);
  EXPECT_TRUE(up->isApprox(base_velodyne.inverse(), 1e-12));
  // Across branches: imu -> velodyne = (base_imu)^-1 base_velodyne.
  const std::optional<Transform> across = TransformBetween(tree, "imu", "velodyne");
  ASSERT_TRUE(across);
  EXPECT_TRUE(across->isApprox(tree[2].parent_child.inverse() * base_velodyne, 1e-12));
  EXPECT_TRUE(TransformBetween(tree, "mount", "/mount")->isIdentity());
}

TEST(FrameTree, NoPathIsNothing) {
  std::vector<FrameTransform> tree = Robot();
  EXPECT_FALSE(TransformBetween(tree, "base_link", "camera"));
  tree.push_back({"odom", "camera", Transform::Identity()});
  EXPECT_FALSE(TransformBetween(tree, "base_link", "camera"));  // another tree
  EXPECT_FALSE(TransformBetween({}, "base_link", "velodyne"));
}

TEST(FrameTree, ALaterTransformReplacesAnEarlierOne) {
  std::vector<FrameTransform> tree = Robot();
  const Transform remounted = Pose(0, 0, M_PI, {0.5, 0, 0});
  tree.push_back({"mount", "velodyne", remounted});
  EXPECT_TRUE(TransformBetween(tree, "mount", "velodyne")->isApprox(remounted, 1e-12));
}

TEST(FrameTree, ACycleIsAnInputError) {
  const std::vector<FrameTransform> cycle = {{"a", "b", Transform::Identity()},
                                             {"b", "a", Transform::Identity()},
                                             {"c", "d", Transform::Identity()}};
  EXPECT_THROW(TransformBetween(cycle, "a", "d"), InputError);
}

}  // namespace
}  // namespace boicp
