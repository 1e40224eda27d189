// The shared stages around the search: per-pair preparation and the
// coarse-to-fine refinement every initialiser ends with.

#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "boicp/icp/preprocess.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/refinement.hpp"

namespace boicp {
namespace {

BoIcpConfig StreetConfig() {
  BoIcpConfig config = PresetConfig("C");
  config.voxel = 0.6;
  config.refine_voxel = 0.1;
  return config;
}

TEST(Refinement, PyramidHalvesFromTheSearchVoxelDownToTheRefineVoxel) {
  const Points street = MakeSyntheticStreet(5, 20.0);
  BoIcpConfig config = StreetConfig();
  config.refine_source_points = 0;
  const PreparedPair pair = PreparePair(street, street, config);
  ASSERT_EQ(pair.pyramid.size(), 3u);  // 0.3, 0.15, then the 0.1 refine voxel
  EXPECT_DOUBLE_EQ(pair.pyramid[0].voxel, 0.3);
  EXPECT_DOUBLE_EQ(pair.pyramid[1].voxel, 0.15);
  EXPECT_DOUBLE_EQ(pair.pyramid[2].voxel, 0.1);
  EXPECT_LT(pair.search_source.size(), pair.pyramid[0].source.size());
  EXPECT_LT(pair.pyramid[0].source.size(), pair.pyramid[2].source.size());
}

TEST(Refinement, LevelSourcesKeepAtMostRefineSourcePointsAndTargetsKeepAll) {
  const Points street = MakeSyntheticStreet(5, 20.0);
  BoIcpConfig config = StreetConfig();
  config.refine_source_points = 0;  // all
  const PreparedPair all = PreparePair(street, street, config);
  const size_t finest = all.pyramid.back().source.size();
  ASSERT_GT(finest, 1000u);
  EXPECT_EQ(finest, all.pyramid.back().target.size());

  config.refine_source_points = 1000;
  const PreparedPair capped = PreparePair(street, street, config);
  for (size_t k = 0; k < capped.pyramid.size(); ++k) {
    EXPECT_EQ(capped.pyramid[k].source.size(),
              std::min<size_t>(1000, all.pyramid[k].source.size()));
    EXPECT_EQ(capped.pyramid[k].target.size(), all.pyramid[k].target.size());
  }
  EXPECT_EQ(capped.search_source.size(), all.search_source.size());
}

void ExpectSamePoints(const Points& expected, const Points& actual, const std::string& what) {
  ASSERT_EQ(expected.size(), actual.size()) << what;
  for (size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(expected[i], actual[i]) << what << ", point " << i;  // bit for bit, in order
  }
}

void ExpectSamePreparedPair(const PreparedPair& expected, const PreparedPair& actual) {
  EXPECT_EQ(expected.source_centre, actual.source_centre);
  EXPECT_EQ(expected.target_centre, actual.target_centre);
  ExpectSamePoints(expected.search_source, actual.search_source, "search source");
  ExpectSamePoints(expected.search_target.points(), actual.search_target.points(), "search target");
  ASSERT_EQ(expected.pyramid.size(), actual.pyramid.size());
  for (size_t k = 0; k < expected.pyramid.size(); ++k) {
    EXPECT_EQ(expected.pyramid[k].voxel, actual.pyramid[k].voxel);
    ExpectSamePoints(expected.pyramid[k].source, actual.pyramid[k].source, "level source");
    ExpectSamePoints(expected.pyramid[k].target.points(), actual.pyramid[k].target.points(),
                     "level target");
  }
}

// Pairs that share a scan share its pyramid: a pair prepared from pyramids
// is the pair prepared from the raw scans, also for a config whose search
// voxel the pyramids do not hold (a retry's), which is downsampled anew.
TEST(Refinement, PairsPreparedFromScanPyramidsAreThePairsPreparedFromTheScans) {
  const Points source = MakeSyntheticStreet(5, 20.0);
  const Points target = TransformPoints(PoseFromYawTranslation(0.3, {1.0, 0.5, 0.0}), source);
  BoIcpConfig config = StreetConfig();
  config.max_range = 25.0;
  config.refine_source_points = 2000;
  const ScanPyramid source_pyramid = BuildScanPyramid(source, config);
  const ScanPyramid target_pyramid = BuildScanPyramid(target, config);
  EXPECT_EQ(source_pyramid.voxels, PyramidVoxels(config));
  ExpectSamePreparedPair(PreparePair(source, target, config, 9),
                         PreparePair(source_pyramid, target_pyramid, config, 9));

  BoIcpConfig retry = config;
  retry.voxel = 1.2;  // refinement levels 0.6, 0.3, 0.15, then the same 0.1
  ExpectSamePreparedPair(PreparePair(source, target, retry, 9),
                         PreparePair(source_pyramid, target_pyramid, retry, 9));

  BoIcpConfig nearer = config;
  nearer.max_range = 20.0;
  EXPECT_THROW(PreparePair(source_pyramid, target_pyramid, nearer), std::invalid_argument);
}

// A street scan and the same scan moved by `truth`^-1, so T_target_source = truth.
struct KnownPair {
  Transform truth;
  BoIcpConfig config;
  PreparedPair pair;
};

KnownPair MakeKnownPair() {
  const Transform truth = PoseFromYawTranslation(0.05, {0.4, -0.3, 0.0});
  const BoIcpConfig config = StreetConfig();
  const Points target =
      SimulateScan(MakeSyntheticStreet(7, 30.0), Transform::Identity(), 40.0, 0.0, 1);
  return {truth, config, PreparePair(TransformPoints(truth.inverse(), target), target, config)};
}

// Refines from `starts` given between the scans' frames, as RegisterPair
// does: the pair's clouds are centred, and so is the refinement.
RefinedAlignment RefineFrom(const KnownPair& known, std::vector<Transform> starts) {
  const PreparedPair& pair = known.pair;
  for (Transform& start : starts) {
    start = CentredTransform(pair.source_centre, pair.target_centre, start);
  }
  RefinedAlignment refined = RefineCoarseToFine(starts, pair, known.config);
  refined.transform = UncentredTransform(pair.source_centre, pair.target_centre, refined.transform);
  return refined;
}

TEST(Refinement, RecoversATransformFromAStartInsideTheBasin) {
  const KnownPair known = MakeKnownPair();
  const Transform& truth = known.truth;
  const RefinedAlignment refined = RefineFrom(known, {Transform::Identity()});
  EXPECT_LT(RotationAngle(refined.transform.inverse() * truth), 1e-3);
  EXPECT_LT(TranslationNorm(refined.transform.inverse() * truth), 0.01);
  EXPECT_GT(refined.score.fitness, 0.99);
}

TEST(Refinement, TheStartThatFitsBestWinsWhateverItsPlaceInTheList) {
  const KnownPair known = MakeKnownPair();
  const Transform& truth = known.truth;
  const PreparedPair& pair = known.pair;
  const BoIcpConfig& config = known.config;
  const Transform wrong = PoseFromYawTranslation(M_PI, {3.0, 1.0, 0.0});  // another basin

  for (const std::vector<Transform>& starts :
       {std::vector<Transform>{Transform::Identity(), wrong},
        std::vector<Transform>{wrong, Transform::Identity()}}) {
    const RefinedAlignment refined = RefineFrom(known, starts);
    EXPECT_LT(RotationAngle(refined.transform.inverse() * truth), 1e-3);
    EXPECT_LT(TranslationNorm(refined.transform.inverse() * truth), 0.01);
  }
  EXPECT_THROW(RefineCoarseToFine({}, pair, config), InputError);
}

// The margin compares the answer with another basin; where nothing was
// compared, or nothing fits, there is no margin to claim.
TEST(Refinement, MarginNeedsARunnerUpAndInliers) {
  const KnownPair known = MakeKnownPair();
  const PreparedPair& pair = known.pair;
  const BoIcpConfig& config = known.config;
  const Transform wrong = PoseFromYawTranslation(M_PI, {3.0, 1.0, 0.0});

  // A single start: nothing to compare with, however well it fits.
  const RefinedAlignment alone = RefineCoarseToFine({Transform::Identity()}, pair, config);
  EXPECT_GT(alone.score.fitness, 0.99);
  EXPECT_EQ(alone.margin, 0.0);
  EXPECT_FALSE(alone.margin_measured);

  // A clearly worse basin beside it: the margin is large but measured.
  const RefinedAlignment compared =
      RefineCoarseToFine({Transform::Identity(), wrong}, pair, config);
  EXPECT_GT(compared.margin, 0.5);
  EXPECT_LT(compared.margin, 1.0);
  EXPECT_TRUE(compared.margin_measured);

  // Starts 100 m away from every point: no inliers, no margin.
  Transform far = Transform::Identity();
  far(0, 3) = 100.0;
  Transform farther = far;
  farther(1, 3) = 100.0;
  const RefinedAlignment nothing = RefineCoarseToFine({far, farther}, pair, config);
  EXPECT_EQ(nothing.score.fitness, 0.0);
  EXPECT_EQ(nothing.margin, 0.0);
  EXPECT_FALSE(nothing.margin_measured);
}

TEST(Refinement, RmsRadiusOfACubesCornersIsItsHalfDiagonal) {
  Points corners;
  for (double x : {-1.0, 1.0})
    for (double y : {-1.0, 1.0})
      for (double z : {-1.0, 1.0}) corners.push_back(Point(x, y, z) * 0.5 + Point(3.0, -2.0, 7.0));
  EXPECT_NEAR(RmsRadius(corners), 0.5 * std::sqrt(3.0), 1e-12);
  EXPECT_EQ(RmsRadius({}), 0.0);
}

// The confidence reads how finely the finest level can place a rotation:
// the angle that moves a point at the source's RMS radius by one voxel.
TEST(Refinement, ResolutionIsOneRefineVoxelSeenFromTheSourcesRmsRadius) {
  const KnownPair known = MakeKnownPair();
  const Points& finest = known.pair.pyramid.back().source;
  const RefinedAlignment refined =
      RefineCoarseToFine({Transform::Identity()}, known.pair, known.config);
  EXPECT_NEAR(refined.resolution_deg, std::atan(0.1 / RmsRadius(finest)) * 180.0 / M_PI, 1e-9);

  BoIcpConfig finer = known.config;
  finer.refine_voxel = 0.05;
  const PreparedPair finer_pair = PreparePair(finest, finest, finer);
  const double halved =
      RefineCoarseToFine({Transform::Identity()}, finer_pair, finer).resolution_deg;
  EXPECT_GT(halved, 0.4 * refined.resolution_deg);
  EXPECT_LT(halved, 0.6 * refined.resolution_deg);
}

TEST(Refinement, CloudEmptiedByCroppingIsAnInputErrorNamingIt) {
  const Points street = MakeSyntheticStreet(5, 20.0);
  Points beyond_range = street;
  for (Point& p : beyond_range) p.x() += 1000.0;
  BoIcpConfig config = StreetConfig();
  config.max_range = 100.0;
  try {
    PreparePair(street, beyond_range, config);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("target cloud has 0 points"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace boicp
