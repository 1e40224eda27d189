// The information matrix of a registered pair, and the one RegisterPair
// reports with its answer.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "boicp/icp/pair_information.hpp"
#include "boicp/icp/surface_normals.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "boicp/registration/refinement.hpp"
#include "evaluation.hpp"

namespace boicp {
namespace {

TEST(PlaneInformation, SumsEachMatchAlongItsNormalAndVanishesWithoutOverlap) {
  const Points world = MakeSyntheticStreet(3, 10.0);
  const Points scan =
      SimulateScan(world, PoseFromYawTranslation(0.0, Eigen::Vector3d::Zero()), 20.0, 0.0, 1);
  const NearestNeighborIndex index(scan);
  const InformationMatrix info = PlaneInformation(scan, index, Transform::Identity(), 0.3, 1.0);
  // Every point matches itself: each adds J^T J with J = (q x n, n).
  InformationMatrix expected = InformationMatrix::Zero();
  for (const Point& q : scan) {
    const Point n = SurfaceNormalAt(index, q, 1.0);
    Eigen::Matrix<double, 6, 1> jacobian;
    jacobian << q.cross(n), n;
    expected += jacobian * jacobian.transpose();
  }
  EXPECT_TRUE(info.isApprox(expected, 1e-9));
  EXPECT_GT(info.bottomRightCorner(3, 3).trace(), 0.5 * static_cast<double>(scan.size()));
  const InformationMatrix none =
      PlaneInformation(scan, index, PoseFromYawTranslation(0.0, {0.0, 100.0, 0.0}), 0.3, 1.0);
  EXPECT_TRUE(none.isZero());
}

// RegisterPair measures the information on centred clouds; moved back to
// the scans' frames it is what the scans' own points give.
TEST(PlaneInformation, MovedInformationIsThatOfTheMovedTargetPoints) {
  const Points world = MakeSyntheticStreet(3, 10.0);
  const Transform T = PoseFromYawTranslation(0.1, {0.5, -0.2, 0.0});
  const Points target = SimulateScan(world, Transform::Identity(), 20.0, 0.0, 1);
  const Points source = TransformPoints(T.inverse(), target);
  const Point offset(1200.0, -800.0, 35.0);
  Transform moved_T = T;
  moved_T.topRightCorner<3, 1>() += offset;
  const InformationMatrix expected =
      PlaneInformation(source, NearestNeighborIndex(TransformPoints(moved_T * T.inverse(), target)),
                       moved_T, 0.3, 1.0);
  const InformationMatrix moved =
      MovedInformation(PlaneInformation(source, NearestNeighborIndex(target), T, 0.3, 1.0), offset);
  EXPECT_GT(expected(3, 3), 100.0);
  EXPECT_TRUE(moved.isApprox(expected, 1e-6)) << moved << "\n\n" << expected;
}

// The answer's information counts the finest level's inliers, the same
// points its fitness is the share of.
TEST(PlaneInformation, RegisterPairReportsItForTheFinestLevelInliers) {
  const Points world = MakeSyntheticStreet(11, 15.0);
  const Transform T_world_target = PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8});
  const Transform T_world_source = PoseFromYawTranslation(0.4, {1.2, 0.4, 1.8});
  const Points source = SimulateScan(world, T_world_source, 30.0, 0.01, 1);
  const Points target = SimulateScan(world, T_world_target, 30.0, 0.01, 2);
  BoIcpConfig config = PresetConfig("A");
  config.automatic.clear();
  config.retry_when_doubtful = false;
  config.seed = 3;
  const RegistrationResult result = RegisterPair(source, target, config);
  ASSERT_LT(RotationErrorDeg(result.transform, T_world_target.inverse() * T_world_source), 1.0);

  const size_t finest_points = PreparePair(source, target, config).pyramid.back().source.size();
  const double inliers = result.fitness * static_cast<double>(finest_points);
  EXPECT_GT(inliers, 100.0);
  // Point-to-plane: each inlier with a normal adds 1 to the translation
  // block's trace.
  const double with_normals = result.information.bottomRightCorner<3, 3>().trace();
  EXPECT_LE(with_normals, inliers + 0.5);
  EXPECT_GT(with_normals, 0.8 * inliers);
  const Eigen::SelfAdjointEigenSolver<InformationMatrix> spectrum(result.information);
  EXPECT_GT(spectrum.eigenvalues().minCoeff(), 0.0);
}

// A flat wall pins the pose down only across itself: sliding along it, or
// turning about its normal, moves no match off its plane.
TEST(PlaneInformation, AWallLeavesItsOwnDirectionsFree) {
  Points wall;
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 40; ++j) wall.emplace_back(5.0, -3.0 + 0.1 * i, -1.0 + 0.05 * j);
  }
  const NearestNeighborIndex index(wall);
  const InformationMatrix info = PlaneInformation(wall, index, Transform::Identity(), 0.2, 0.3);
  const Eigen::Matrix3d translation = info.bottomRightCorner<3, 3>();
  EXPECT_NEAR(translation(0, 0), static_cast<double>(wall.size()), 1e-6);  // across the wall
  EXPECT_NEAR(translation(1, 1), 0.0, 1e-9);
  EXPECT_NEAR(translation(2, 2), 0.0, 1e-9);
  const Eigen::SelfAdjointEigenSolver<InformationMatrix> spectrum(info);
  // Three directions of 6 are free: two slides and the turn about x.
  EXPECT_NEAR(spectrum.eigenvalues()(2), 0.0, 1e-6 * spectrum.eigenvalues()(5));

  // A street's scan constrains every direction (its rotation block, in m^2,
  // is hundreds of times its translation block: hence the small ratio).
  const Points street = SimulateScan(MakeSyntheticStreet(3, 10.0),
                                     PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8}), 20.0, 0.0, 1);
  const InformationMatrix street_info =
      PlaneInformation(street, NearestNeighborIndex(street), Transform::Identity(), 0.3, 1.0);
  const Eigen::SelfAdjointEigenSolver<InformationMatrix> street_spectrum(street_info);
  EXPECT_GT(street_spectrum.eigenvalues()(0), 1e-4 * street_spectrum.eigenvalues()(5));
}

}  // namespace
}  // namespace boicp
