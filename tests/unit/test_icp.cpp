// ICP (point-to-point and point-to-plane), surface normals, the alignment
// score and the search box on synthetic data.

#include <gtest/gtest.h>

#include "boicp/icp/alignment_score.hpp"
#include "boicp/icp/icp.hpp"
#include "boicp/icp/preprocess.hpp"
#include "boicp/icp/surface_normals.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/search_space.hpp"

namespace boicp {
namespace {

Transform SmallMotion() {
  Transform T = Transform::Identity();
  T.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.08, Eigen::Vector3d(0.2, 0.3, 1.0).normalized()).toRotationMatrix();
  T.topRightCorner<3, 1>() = Eigen::Vector3d(0.3, -0.2, 0.05);
  return T;
}

Points StreetSample() { return VoxelDownsample(MakeSyntheticStreet(3, 20.0), 0.3); }

// The street as target and the street moved by SmallMotion()^-1 as source.
struct MovedStreet {
  Points target = StreetSample();
  Points source = TransformPoints(SmallMotion().inverse(), target);
  NearestNeighborIndex index{target};
};

TEST(Icp, RecoversKnownSmallTransformExactlyOnNoiselessData) {
  const Points target = StreetSample();
  const Transform truth = SmallMotion();
  // source = truth^-1 * target, so T_target_source = truth exactly.
  const Points source = TransformPoints(truth.inverse(), target);
  const NearestNeighborIndex index(target);
  IcpOptions options;
  options.max_correspondence_distance = 2.0;
  options.max_iterations = 100;
  options.convergence_translation = 1e-9;
  options.convergence_rotation = 1e-10;
  const IcpResult result = AlignPointToPoint(source, index, Transform::Identity(), options);
  EXPECT_LT(RotationAngle(result.transform.inverse() * truth), 1e-6);
  EXPECT_LT(TranslationNorm(result.transform.inverse() * truth), 1e-6);
  EXPECT_LT(result.rmse, 1e-6);
  EXPECT_EQ(result.correspondences, source.size());
}

TEST(Icp, SerialAndParallelGiveIdenticalResults) {
  const MovedStreet street;
  const Points& source = street.source;
  const NearestNeighborIndex& index = street.index;
  IcpOptions serial;
  serial.max_correspondence_distance = 1.0;
  IcpOptions parallel = serial;
  parallel.threads = 2;
  const IcpResult a = AlignPointToPoint(source, index, Transform::Identity(), serial);
  const IcpResult b = AlignPointToPoint(source, index, Transform::Identity(), parallel);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.correspondences, b.correspondences);
  EXPECT_TRUE(a.transform == b.transform) << a.transform << "\nvs\n" << b.transform;
  const AlignmentScore sa = ScoreAlignment(source, index, a.transform, 0.5, 1);
  const AlignmentScore sb = ScoreAlignment(source, index, a.transform, 0.5, 2);
  EXPECT_EQ(sa.truncated_mean, sb.truncated_mean);
  EXPECT_EQ(sa.fitness, sb.fitness);
}

// A street sample started 2 m along the street (where point-to-point ICP
// creeps): the extrapolating run ends where the plain one does, within the
// convergence tolerances' reach, in fewer iterations, and its parallel twin
// gives the same bits.
TEST(Icp, ExtrapolationReachesTheSameAnswerInFewerIterations) {
  const MovedStreet street;
  Transform start = SmallMotion();
  start(0, 3) += 2.0;
  IcpOptions plain;
  plain.max_correspondence_distance = 3.0;
  plain.max_iterations = 200;
  plain.convergence_translation = 1e-5;
  plain.convergence_rotation = 1e-6;
  IcpOptions extrapolating = plain;
  extrapolating.extrapolate = true;
  const IcpResult a = AlignPointToPoint(street.source, street.index, start, plain);
  const IcpResult b = AlignPointToPoint(street.source, street.index, start, extrapolating);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  EXPECT_LT(TranslationNorm(a.transform.inverse() * b.transform), 1e-3);
  EXPECT_LT(RotationAngle(a.transform.inverse() * b.transform), 1e-4);
  EXPECT_LT(TranslationNorm(SmallMotion().inverse() * b.transform), 1e-3);
  EXPECT_LT(b.iterations, a.iterations);

  extrapolating.threads = 2;
  const IcpResult twin = AlignPointToPoint(street.source, street.index, start, extrapolating);
  EXPECT_EQ(twin.iterations, b.iterations);
  EXPECT_TRUE(twin.transform == b.transform);
}

// A tilted plane sampled on a grid: every normal is the plane's (up to
// sign); a line of points has none.
TEST(SurfaceNormals, AreThePlanesNormalAndZeroOnALine) {
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  Points plane;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) plane.push_back(0.1 * i * u + 0.1 * j * v);
  }
  const Points normals = EstimateSurfaceNormals(NearestNeighborIndex(plane), 0.3, 2);
  ASSERT_EQ(normals.size(), plane.size());
  for (const Point& n : normals) EXPECT_NEAR(std::abs(n.dot(normal)), 1.0, 1e-9);

  Points line;
  for (int i = 0; i < 20; ++i) line.push_back(Point(0.1 * i, 0.0, 0.0));
  for (const Point& n : EstimateSurfaceNormals(NearestNeighborIndex(line), 0.3, 1)) {
    EXPECT_TRUE(n.isZero());
  }
}

// On the street, point-to-plane reaches the same transform as point-to-point
// in fewer iterations, and its result does not depend on the thread count.
TEST(Icp, PointToPlaneConvergesInFewerIterationsToTheSameTransform) {
  const MovedStreet street;
  const Points normals = EstimateSurfaceNormals(street.index, 0.9, 1);
  IcpOptions options;
  options.max_correspondence_distance = 1.0;
  options.max_iterations = 100;
  options.convergence_translation = 1e-6;
  options.convergence_rotation = 1e-7;
  const IcpResult point =
      AlignPointToPoint(street.source, street.index, Transform::Identity(), options);
  const IcpResult plane =
      AlignPointToPlane(street.source, street.index, normals, Transform::Identity(), options);
  ASSERT_TRUE(point.converged);
  ASSERT_TRUE(plane.converged);
  EXPECT_LT(RotationAngle(plane.transform.inverse() * SmallMotion()), 1e-4);
  EXPECT_LT(TranslationNorm(plane.transform.inverse() * SmallMotion()), 1e-3);
  EXPECT_LT(plane.iterations * 2, point.iterations)
      << plane.iterations << " point-to-plane iterations vs " << point.iterations;

  IcpOptions parallel = options;
  parallel.threads = 2;
  const IcpResult twin =
      AlignPointToPlane(street.source, street.index, normals, Transform::Identity(), parallel);
  EXPECT_TRUE(twin.transform == plane.transform);
  EXPECT_EQ(twin.iterations, plane.iterations);
  EXPECT_THROW(AlignPointToPlane(street.source, street.index, Points(3, Point::UnitZ()),
                                 Transform::Identity(), options),
               InputError);
}

TEST(Icp, ProjectedLimitExtrapolatesTheFasterOfTheLastTwoSteps) {
  EXPECT_NEAR(ProjectedLimit(1.0, 0.8, 0.7, 3), 0.7 - 0.2 * 3, 1e-12);
  EXPECT_NEAR(ProjectedLimit(1.0, 0.9, 0.7, 2), 0.7 - 0.2 * 2, 1e-12);
  EXPECT_DOUBLE_EQ(ProjectedLimit(0.5, 0.6, 0.6, 10), 0.6);  // not decreasing: stays
  EXPECT_DOUBLE_EQ(ProjectedLimit(1.0, 0.8, 0.7, 0), 0.7);   // no steps left
}

TEST(Icp, AbandonsOnlyRunsThatCannotBeatTheBound) {
  const MovedStreet street;
  const Points& source = street.source;
  const NearestNeighborIndex& index = street.index;
  IcpOptions options;
  options.max_correspondence_distance = 1.0;
  options.max_iterations = 40;
  const IcpResult full = AlignPointToPoint(source, index, Transform::Identity(), options);
  ASSERT_FALSE(full.abandoned);
  const double start = ScoreAlignment(source, index, Transform::Identity(), 0.5).truncated_mean;
  ASSERT_LT(ScoreAlignment(source, index, full.transform, 0.5).truncated_mean, start);

  options.truncation = 0.5;
  // A bound the run is below from its first step: it runs exactly as without one.
  options.abandon_above = start;
  const IcpResult bounded = AlignPointToPoint(source, index, Transform::Identity(), options);
  EXPECT_FALSE(bounded.abandoned);
  EXPECT_TRUE(bounded.transform == full.transform);
  EXPECT_EQ(bounded.iterations, full.iterations);

  // A bound below anything reachable: given up after abandon_after iterations,
  // and the score there is above the bound.
  options.abandon_above = -1.0;
  const IcpResult hopeless = AlignPointToPoint(source, index, Transform::Identity(), options);
  EXPECT_TRUE(hopeless.abandoned);
  EXPECT_EQ(hopeless.iterations, options.abandon_after);
  EXPECT_GT(ScoreAlignment(source, index, hopeless.transform, 0.5).truncated_mean, -1.0);

  options.truncation = 2.0;  // beyond the gate: distances there were never measured
  EXPECT_THROW(AlignPointToPoint(source, index, Transform::Identity(), options), InputError);
}

TEST(Icp, JoinsAKnownEndOnlyWithinTheJoinRadii) {
  const MovedStreet street;
  const Points& source = street.source;
  const NearestNeighborIndex& index = street.index;
  IcpOptions options;
  options.max_correspondence_distance = 1.0;
  options.max_iterations = 60;
  const IcpResult own = AlignPointToPoint(source, index, Transform::Identity(), options);
  ASSERT_TRUE(own.converged);
  ASSERT_GT(own.iterations, 3);
  Transform elsewhere = own.transform;
  elsewhere(0, 3) += 5.0;
  const std::vector<Transform> ends = {elsewhere, own.transform};

  // Radii off: the run ignores the known ends and repeats its own path.
  const IcpResult unjoined = AlignPointToPoint(source, index, Transform::Identity(), options, ends);
  EXPECT_EQ(unjoined.joined_end, -1);
  EXPECT_TRUE(unjoined.transform == own.transform);
  EXPECT_EQ(unjoined.iterations, own.iterations);

  // With radii the run stops where it enters the second end's neighbourhood,
  // sooner, and returns that end exactly.
  options.join_translation = 0.05;
  options.join_rotation = 0.01;
  const IcpResult joined = AlignPointToPoint(source, index, Transform::Identity(), options, ends);
  EXPECT_EQ(joined.joined_end, 1);
  EXPECT_TRUE(joined.converged);
  EXPECT_TRUE(joined.transform == own.transform);
  EXPECT_LT(joined.iterations, own.iterations);

  // A start outside every neighbourhood that converges far from the known
  // ends runs to its own end.
  const IcpResult far =
      AlignPointToPoint(source, index, Transform::Identity(), options, {elsewhere});
  EXPECT_EQ(far.joined_end, -1);
  EXPECT_TRUE(far.transform == own.transform);
}

TEST(Icp, StopsWithoutCorrespondences) {
  const Points target = {Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0)};
  const Points source = {Point(100, 0, 0), Point(101, 0, 0), Point(100, 1, 0)};
  const NearestNeighborIndex index(target);
  const IcpResult result = AlignPointToPoint(source, index, Transform::Identity(), IcpOptions{});
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.correspondences, 0u);
  EXPECT_TRUE(result.transform.isIdentity());
}

TEST(AlignmentScore, ClipsDistancesAtTau) {
  const Points target = {Point(0, 0, 0)};
  const NearestNeighborIndex index(target);
  // Distances 0.1 and 5.0; tau 1.0 -> clipped mean (0.1 + 1.0) / 2.
  const Points source = {Point(0.1, 0, 0), Point(5, 0, 0)};
  const AlignmentScore score = ScoreAlignment(source, index, Transform::Identity(), 1.0);
  EXPECT_NEAR(score.truncated_mean, 0.55, 1e-12);
  EXPECT_NEAR(score.fitness, 0.5, 1e-12);
  EXPECT_NEAR(score.inlier_rmse, 0.1, 1e-12);
}

TEST(SearchSpace, CentreIsTheAnchorAndRollYawWrap) {
  Transform anchor = SmallMotion();
  const SearchSpace space =
      MakeSearchSpace(anchor, Point(1, 2, 3), {M_PI, M_PI / 2, M_PI}, Eigen::Vector3d::Zero());
  ASSERT_EQ(space.dimension(), 3);
  EXPECT_TRUE(space.ToTransform(Eigen::Vector3d::Constant(0.5)).isApprox(anchor, 1e-12));
  EXPECT_EQ(space.Inputs(), KernelInputs({true, false, true}));
  // u = 0 and u = 1 on roll and yaw are the same rotation (-pi == +pi).
  const Transform low = space.ToTransform(Eigen::Vector3d(0.0, 0.3, 0.0));
  const Transform high = space.ToTransform(Eigen::Vector3d(1.0, 0.3, 1.0));
  EXPECT_TRUE(low.isApprox(high, 1e-9));
  // The pivot, mapped by the anchor's offset rotation, stays where it is.
  const Transform some = space.ToTransform(Eigen::Vector3d(0.2, 0.7, 0.9));
  const Transform offset = some * anchor.inverse();
  const Point moved_pivot = TransformPoints(offset, {Point(1, 2, 3)}).front();
  EXPECT_TRUE(moved_pivot.isApprox(Point(1, 2, 3), 1e-9));
}

TEST(SearchSpace, ZeroHalfWidthsAreNotSearched) {
  const SearchSpace space = MakeSearchSpace(Transform::Identity(), Point::Zero(),
                                            Eigen::Vector3d::Zero(), Eigen::Vector3d(4, 2, 0));
  EXPECT_EQ(space.dimension(), 2);
  const Transform corner = space.ToTransform(Eigen::Vector2d(1.0, 0.0));
  const Eigen::Vector3d translation = corner.topRightCorner<3, 1>();
  EXPECT_TRUE(translation.isApprox(Eigen::Vector3d(4, -2, 0)));
}

}  // namespace
}  // namespace boicp
