// The search over every rotation: rotation-vector coordinates, their kernel,
// the uniform initial rotations and a Bayesian optimisation over SO(3). The
// likelihood's gradient is checked with the others in test_gaussian_process.cpp.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "boicp/bo/bayes_opt.hpp"
#include "boicp/bo/gaussian_process.hpp"
#include "boicp/bo/kernel_inputs.hpp"
#include "boicp/bo/sampling.hpp"
#include "boicp/registration/search_space.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

constexpr InputKind kR = InputKind::kRotation;
constexpr InputKind kL = InputKind::kLinear;

double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

Eigen::Matrix3d SomeRotation(double roll, double pitch, double yaw) {
  return RotationFromEuler(roll, pitch, yaw);
}

TEST(KernelInputs, RotationsComeInRunsOfThreeWithOneLengthScale) {
  const KernelInputs inputs({kR, kR, kR, kL});
  EXPECT_EQ(inputs.dimension(), 4);
  EXPECT_EQ(inputs.EmbeddedWidth(0), 9);
  EXPECT_TRUE(inputs.StartsRotation(0));
  EXPECT_FALSE(inputs.StartsRotation(1));
  EXPECT_EQ(inputs.EmbeddedWidth(1), 0);
  EXPECT_TRUE(inputs.TiedLengthScale(2));
  EXPECT_EQ(inputs.EmbeddedWidth(3), 1);
  EXPECT_EQ(KernelInputs({true, false}).EmbeddedWidth(0), 2);
  EXPECT_THROW(KernelInputs({kR, kR, kL}), InputError);
  EXPECT_THROW(KernelInputs({kR, kR, kR, kR}), InputError);
  EXPECT_NO_THROW(KernelInputs({kR, kR, kR, kR, kR, kR}));
}

TEST(RotationCoordinates, RoundTripEveryRotationInsideTheCube) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d u = UniformPoints(1, 3, rng).row(0).transpose();
    const Eigen::Matrix3d R = RotationFromUnit(u);
    const Eigen::Vector3d back = UnitFromRotation(R);
    EXPECT_TRUE((back.array() >= 0.0).all() && (back.array() <= 1.0).all()) << back.transpose();
    EXPECT_LT(AngleBetween(RotationFromUnit(back), R), 1e-9);
  }
  EXPECT_TRUE(RotationFromUnit(Eigen::Vector3d::Constant(0.5)).isIdentity(1e-15));
  // Half a turn about x: both ends of the cube's x axis are the same rotation.
  EXPECT_LT(AngleBetween(RotationFromUnit({0.0, 0.5, 0.5}), RotationFromUnit({1.0, 0.5, 0.5})),
            1e-12);
}

TEST(RotationCoordinates, TheKernelSeesOnlyTheGeodesicAngle) {
  // One observation at the identity: the posterior spread at another rotation
  // depends on its angle from the identity alone, whatever the axis, and two
  // names of one rotation are one point.
  GaussianProcess gp(KernelInputs({kR, kR, kR}));
  GpHyperparameters h;
  h.length_scales = Eigen::Vector3d::Constant(0.1);
  h.noise_variance = 1e-6;
  gp.Condition(Eigen::RowVector3d::Constant(0.5), Eigen::VectorXd::Constant(1, 2.0), h);
  const double angle = 0.7;
  const Eigen::Vector3d about_x = UnitFromRotation(SomeRotation(angle, 0, 0));
  const Eigen::Vector3d about_tilted = UnitFromRotation(
      Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, -3).normalized()).toRotationMatrix());
  EXPECT_NEAR(gp.Predict(about_x).std, gp.Predict(about_tilted).std, 1e-9);
  EXPECT_LT(gp.Predict(about_x).std, gp.Predict(UnitFromRotation(SomeRotation(1.4, 0, 0))).std);
  EXPECT_NEAR(gp.Predict(Eigen::Vector3d(0.0, 0.5, 0.5)).mean,
              gp.Predict(Eigen::Vector3d(1.0, 0.5, 0.5)).mean, 1e-12);
}

TEST(UniformRotations, SpreadEvenlyAndReproducibly) {
  std::mt19937_64 a(5), b(5), c(6);
  const Eigen::MatrixXd U = UniformRotations(60, a);
  EXPECT_EQ(U, UniformRotations(60, b));
  EXPECT_NE(U, UniformRotations(60, c));  // another seed turns the whole set
  std::vector<Eigen::Matrix3d> rotations;
  Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < U.rows(); ++i) {
    rotations.push_back(RotationFromUnit(U.row(i).transpose()));
    mean += rotations.back() / static_cast<double>(U.rows());
  }
  // Uniform rotations average to the zero matrix.
  EXPECT_LT(mean.norm(), 0.15);
  // Evenly spread: no two within 30 degrees (the spiral's closest pair is 38
  // degrees apart; of 60 rotations drawn independently, about 10, and in 50
  // draws never over 23).
  double closest = M_PI;
  for (size_t i = 0; i < rotations.size(); ++i) {
    for (size_t j = i + 1; j < rotations.size(); ++j) {
      closest = std::min(closest, AngleBetween(rotations[i], rotations[j]));
    }
  }
  EXPECT_GT(closest, 30.0 * M_PI / 180.0);
}

TEST(SearchSpace, ARotationVectorBoxHoldsEveryRotationOnce) {
  Transform anchor = Transform::Identity();
  anchor.topRightCorner<3, 1>() = Eigen::Vector3d(3, -1, 2);
  const Point pivot(1, 2, 3);
  const SearchSpace space =
      MakeSearchSpace(anchor, pivot, {M_PI, M_PI / 2, M_PI}, Eigen::Vector3d(4, 2, 1),
                      RotationCoordinates::kRotationVector);
  ASSERT_TRUE(space.rotation_vector);
  EXPECT_EQ(space.Inputs(), KernelInputs({kR, kR, kR, kL, kL, kL}));
  EXPECT_TRUE(space.ToTransform(Eigen::VectorXd::Constant(6, 0.5)).isApprox(anchor, 1e-12));
  // Near gimbal lock as well as anywhere else, ToUnit names the transform.
  for (const Eigen::Vector3d& euler :
       {Eigen::Vector3d(0.3, 1.55, -2.0), Eigen::Vector3d(3.0, -1.4, 0.1),
        Eigen::Vector3d(-1.0, 0.2, 3.1)}) {
    Transform offset = Transform::Identity();
    const Eigen::Matrix3d R = SomeRotation(euler[0], euler[1], euler[2]);
    offset.topLeftCorner<3, 3>() = R;
    offset.topRightCorner<3, 1>() = pivot + Eigen::Vector3d(1.0, -0.5, 0.2) - R * pivot;
    const Transform T = offset * anchor;
    EXPECT_TRUE(space.ToTransform(space.ToUnit(T)).isApprox(T, 1e-9)) << euler.transpose();
  }
  // A box narrower than every rotation keeps the yaw-first Euler angles.
  const SearchSpace narrow =
      MakeSearchSpace(anchor, pivot, {0.2, 0.2, M_PI}, Eigen::Vector3d::Zero(),
                      RotationCoordinates::kRotationVector);
  EXPECT_FALSE(narrow.rotation_vector);
  EXPECT_EQ(narrow.Inputs(), KernelInputs({false, false, true}));
}

// The search finds a rotation anywhere, near gimbal lock and half a turn
// away included, within 10 degrees from 10 uniform samples and 30 steps.
class RotationSearch : public ::testing::TestWithParam<Eigen::Vector3d> {};

TEST_P(RotationSearch, FindsTheRotationAnywhere) {
  const Eigen::Matrix3d target = SomeRotation(GetParam()[0], GetParam()[1], GetParam()[2]);
  const UnitObjective f = [&](const Eigen::VectorXd& u) {
    return AngleBetween(RotationFromUnit(u.head<3>()), target);
  };
  BayesOptOptions options;
  options.initial_samples = 10;
  options.iterations = 30;
  const BayesOptResult result = MinimiseBayesOpt(f, KernelInputs({kR, kR, kR}), options, 17);
  EXPECT_LT(result.best_y, 10.0 * M_PI / 180.0);
}

INSTANTIATE_TEST_SUITE_P(Targets, RotationSearch,
                         ::testing::Values(Eigen::Vector3d(0.4, -0.3, 1.0),
                                           Eigen::Vector3d(0.2, 1.52, -2.5),
                                           Eigen::Vector3d(3.1, 0.05, 3.0),
                                           Eigen::Vector3d(-2.0, -1.2, 0.3)));

}  // namespace
}  // namespace boicp
