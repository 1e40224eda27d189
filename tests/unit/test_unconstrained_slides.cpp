// Which slides a pair's matched surfaces leave free, whether the fit holds
// along the weakest, and what that does to the answer's confidence
// (core/icp/unconstrained_slides, core/icp/slide_rival).

#include <algorithm>

#include <gtest/gtest.h>

#include "boicp/icp/slide_rival.hpp"
#include "boicp/icp/unconstrained_slides.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/pose_graph.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "evaluation.hpp"

namespace boicp {
namespace {

// A plane through `origin` spanned by `u` and `v`, sampled every `step`
// metres over [0, length_u] x [0, length_v].
Points Plane(const Point& origin, const Point& u, const Point& v, double length_u, double length_v,
             double step) {
  Points out;
  for (double a = 0.0; a <= length_u; a += step) {
    for (double b = 0.0; b <= length_v; b += step) out.push_back(origin + a * u + b * v);
  }
  return out;
}

// A corridor along x, 3 m wide and 2.5 m high: a floor and two walls.
Points Corridor(double length) {
  const Point x = Point::UnitX(), y = Point::UnitY(), z = Point::UnitZ();
  Points out = Plane({-length / 2, -1.5, 0.0}, x, y, length, 3.0, 0.1);
  for (const double side : {-1.5, 1.5}) {
    for (const Point& p : Plane({-length / 2, side, 0.0}, x, z, length, 2.5, 0.1)) out.push_back(p);
  }
  return out;
}

InformationMatrix SelfInformation(const Points& points) {
  return PlaneInformation(points, NearestNeighborIndex(points), Transform::Identity(), 0.05, 0.3);
}

bool HasFreeSlide(const std::vector<FreeSlide>& free, const Point& axis) {
  return std::any_of(free.begin(), free.end(),
                     [&](const FreeSlide& s) { return std::abs(s.axis.dot(axis)) > 0.99; });
}

// A wall leaves its two slides free, at the bound of what can be said; the
// slide across it is held: one inlier distance off per inlier distance moved.
TEST(UnconstrainedSlides, AWallLeavesItsTwoSlidesFree) {
  const InformationMatrix wall =
      SelfInformation(Plane({5.0, -3.0, -1.0}, Point::UnitY(), Point::UnitZ(), 6.0, 2.0, 0.05));
  const std::vector<FreeSlide> free = UnconstrainedSlides(wall, 0.05);
  ASSERT_EQ(free.size(), 2u);
  EXPECT_TRUE(HasFreeSlide(free, Point::UnitY()));
  EXPECT_TRUE(HasFreeSlide(free, Point::UnitZ()));
  for (const FreeSlide& s : free) EXPECT_EQ(s.extent, kFreeSlideBound);
  EXPECT_LT(ConstrainedShare(wall), 1e-6);

  const std::vector<FreeSlide> all = PrincipalSlides(wall, 0.05);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_GT(std::abs(all[2].axis.x()), 0.99);
  EXPECT_NEAR(all[2].across_share, 1.0, 1e-6);
  EXPECT_NEAR(all[2].extent, 0.05, 1e-6);
}

// A corridor leaves exactly one slide free, along it, and the pose graph's
// edge barely pulls that way.
TEST(UnconstrainedSlides, ACorridorLeavesOnlyTheSlideAlongIt) {
  const InformationMatrix corridor = SelfInformation(Corridor(20.0));
  const std::vector<FreeSlide> free = UnconstrainedSlides(corridor, 0.05);
  ASSERT_EQ(free.size(), 1u);
  EXPECT_GT(std::abs(free[0].axis.x()), 0.99);
  const std::vector<FreeSlide> all = PrincipalSlides(corridor, 0.05);
  EXPECT_GT(all[1].across_share, 10 * kUnconstrainedShare);

  const InformationMatrix edge = CalibratedInformation(corridor, 0.02);
  EXPECT_LT(edge(3, 3), 1e-2 * edge(4, 4));
  EXPECT_LT(edge(3, 3), 1e-2 * edge(5, 5));
}

// A street holds every slide, wherever its frame's origin (the answer is
// measured on centred clouds). Its weakest slide, along the street, is held
// by the few walls across it: about 5 % of its displacement is across the
// surfaces (4-5 % with GCC and Clang builds), well clear of the free line.
TEST(UnconstrainedSlides, AStreetHoldsEverySlideWhereverItsOrigin) {
  const Points street = SimulateScan(MakeSyntheticStreet(3, 10.0),
                                     PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8}), 20.0, 0.0, 1);
  const InformationMatrix near = SelfInformation(street);
  EXPECT_TRUE(UnconstrainedSlides(near, 0.05).empty());
  EXPECT_GT(ConstrainedShare(near), 3 * kUnconstrainedShare);
  const InformationMatrix far = MovedInformation(near, Point(300.0, -200.0, 10.0));
  EXPECT_NEAR(ConstrainedShare(far), ConstrainedShare(near), 1e-9);
}

// No matches: nothing to say, and nothing held.
TEST(UnconstrainedSlides, NoMatchesNoSlides) {
  EXPECT_TRUE(PrincipalSlides(InformationMatrix::Zero(), 0.05).empty());
  EXPECT_EQ(ConstrainedShare(InformationMatrix::Zero()), 0.0);
}

// A corridor scan slid along itself fits as well wherever it stops: the
// answer is doubtful, and says which way it is free.
TEST(UnconstrainedSlides, ACorridorPairIsDoubtfulAndNamesItsFreeSlide) {
  const Points target = Corridor(30.0);
  Points source;
  for (const Point& p : target) {
    if (std::abs(p.x()) < 10.0) source.push_back(p - Point(0.7, 0.0, 0.0));
  }
  BoIcpConfig config = PresetConfig("A");
  config.automatic.clear();
  config.voxel = 0.2;
  config.refine_voxel = 0.05;
  config.seed = 4;
  const RegistrationResult result =
      RegisterPair(source, target, config, std::nullopt, {}, Transform::Identity());
  EXPECT_TRUE(result.doubtful) << result.confidence;
  EXPECT_LT(result.features.constrained_share, kUnconstrainedShare);
  EXPECT_TRUE(HasFreeSlide(result.unconstrained, Point::UnitX()));
  // The directions it does hold are right: across the corridor and up.
  const Transform truth = PoseFromYawTranslation(0.0, {0.7, 0.0, 0.0});
  EXPECT_LT(RotationErrorDeg(result.transform, truth), 1.0);
  EXPECT_LT(std::abs(result.transform(1, 3)), 0.05);
  EXPECT_LT(std::abs(result.transform(2, 3)), 0.05);
}

// SlideRivalShare: whether the answer is the only place its surfaces fit
// along its weakest slide.

Points Within(const Points& points, double half_length) {
  Points out;
  for (const Point& p : points)
    if (std::abs(p.x()) < half_length) out.push_back(p);
  return out;
}

// Along a corridor the source fits wherever it stops; across it, the walls
// leave and only the floor stays.
TEST(SlideRival, ACorridorKeepsItsFitAlongItButNotAcross) {
  const Points target = Corridor(40.0);
  const Points source = Within(target, 10.0);
  const NearestNeighborIndex index(target);
  EXPECT_GT(SlideRivalShare(source, index, Transform::Identity(), Point::UnitX(), 0.05), 0.98);
  EXPECT_LT(SlideRivalShare(source, index, Transform::Identity(), Point::UnitY(), 0.05), 0.6);
}

// Posts at irregular places along the corridor pin a right answer: a slide
// moves them off, whatever else stays. (Evenly spaced posts would fit again
// a spacing further on.)
TEST(SlideRival, PostsAlongACorridorPinTheAnswer) {
  Points target = Corridor(40.0);
  for (const double x : {-17.3, -11.1, -6.4, -2.2, 3.7, 8.9, 12.6, 18.2}) {
    for (double z = 0.0; z <= 2.5; z += 0.025) {
      for (double a = 0.0; a < 2 * M_PI; a += 0.3)
        target.push_back({x + 0.4 * std::cos(a), 0.4 * std::sin(a), z});
    }
  }
  const Points source = Within(target, 10.0);
  const double rival = SlideRivalShare(source, NearestNeighborIndex(target), Transform::Identity(),
                                       Point::UnitX(), 0.05);
  EXPECT_LT(rival, 0.8);
}

// A source that fits nowhere has no rival to measure, and neither has one
// too short to slide.
TEST(SlideRival, NothingToSlideIsZero) {
  const Points target = Corridor(10.0);
  const NearestNeighborIndex index(target);
  EXPECT_EQ(
      SlideRivalShare(target, index, PoseFromYawTranslation(0.0, {0, 0, 50}), Point::UnitX(), 0.05),
      0.0);
  const Points post = {{0, 0, 0}, {0.01, 0, 0}, {0, 0, 1}};
  EXPECT_EQ(SlideRivalShare(post, index, Transform::Identity(), Point::UnitX(), 0.05), 0.0);
}

// Two stretches of the generated street 80 m apart, with the chain's
// "same place" as the prior: ground and facades fit at the prior, as they
// would a block further on, well enough for the fit alone to be trusted.
// The same scan onto its neighbour is pinned by poles and cars, and
// trusted.
TEST(SlideRival, ALookAlikeStreetIsDoubtfulAndItsNeighbourTrusted) {
  const SyntheticDrive drive(150, 7);
  const SyntheticScan later = drive.Scan(124), earlier = drive.Scan(84), next = drive.Scan(123);
  const BoIcpConfig config = PresetConfig("C");
  const RegistrationResult alike =
      RegisterPair(later.points, earlier.points, config, Transform::Identity());
  const Transform truth = earlier.T_world_scan.inverse() * later.T_world_scan;
  ASSERT_GT(TranslationErrorM(alike.transform, truth), 50.0);
  EXPECT_GT(alike.features.slide_rival, 0.92);
  EXPECT_TRUE(alike.doubtful) << alike.confidence;
  ConfidenceFeatures unprobed = alike.features;
  unprobed.slide_rival = 0.0;
  EXPECT_GE(Confidence(unprobed), kTrustedFrom) << "the probe is what makes it doubtful";

  const RegistrationResult neighbour =
      RegisterPair(later.points, next.points, config, Transform::Identity());
  EXPECT_LT(
      TranslationErrorM(neighbour.transform, next.T_world_scan.inverse() * later.T_world_scan),
      0.1);
  EXPECT_LT(neighbour.features.slide_rival, 0.88);
  EXPECT_FALSE(neighbour.doubtful) << neighbour.confidence;
}

}  // namespace
}  // namespace boicp
