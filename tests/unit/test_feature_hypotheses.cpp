// FPFH descriptors and the RANSAC over their correspondences: descriptors do
// not change when a scan turns about its sensor, hypotheses find a large
// unknown motion between two generated scans, and nothing depends on the
// thread count.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "boicp/icp/preprocess.hpp"
#include "boicp/icp/surface_normals.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/feature_hypotheses.hpp"
#include "boicp/registration/fpfh_features.hpp"

namespace boicp {
namespace {

constexpr double kVoxel = 0.5;  // metres

// A downsampled cloud and its descriptors, as the features rung sees it.
struct DescribedCloud {
  Points points;
  FpfhFeatures features;
};

FpfhFeatures Describe(const Points& points, int threads) {
  const NearestNeighborIndex index(points);
  const Points normals = EstimateSurfaceNormals(index, 2.0 * kVoxel, threads);
  return ComputeFpfhFeatures(index, normals, 5.0 * kVoxel, threads);
}

DescribedCloud DescribedScan(const Points& world, const Transform& T_world_sensor, uint64_t seed) {
  DescribedCloud cloud;
  cloud.points = VoxelDownsample(SimulateScan(world, T_world_sensor, 35.0, 0.02, seed), kVoxel);
  cloud.features = Describe(cloud.points, 1);
  return cloud;
}

FeatureMatchOptions StreetOptions(int threads) {
  FeatureMatchOptions options;
  options.inlier_distance = 2.0 * kVoxel;
  options.distinct_translation = 4.0 * kVoxel;
  options.threads = threads;
  return options;
}

// Two scans of the street whose sensors are `truth` apart: T_target_source.
struct ScanPair {
  DescribedCloud source, target;
};

ScanPair StreetPair(const Transform& truth) {
  const Points world = MakeSyntheticStreet(11, 15.0);
  const Transform T_world_target = PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8});
  return {DescribedScan(world, T_world_target * truth, 1), DescribedScan(world, T_world_target, 2)};
}

double RotationErrorDegrees(const Transform& a, const Transform& b) {
  return RotationAngle(a.inverse() * b) * 180.0 / M_PI;
}

double TranslationError(const Transform& a, const Transform& b) {
  return (a.topRightCorner<3, 1>() - b.topRightCorner<3, 1>()).norm();
}

// Every 11-bin block of every column sums to 100 or to 0.
void ExpectBlocksSumTo100OrZero(const FpfhFeatures& features) {
  for (Eigen::Index i = 0; i < features.cols(); ++i) {
    for (int block = 0; block < 3; ++block) {
      const float sum = features.col(i).segment<11>(11 * block).sum();
      if (sum != 0.0F) {
        EXPECT_NEAR(sum, 100.0F, 1e-3F) << "point " << i << ", block " << block;
      }
    }
  }
}

TEST(FeatureHypotheses, FindALargeYawAndShiftBetweenTwoStreetScans) {
  for (const Transform& truth : {PoseFromYawTranslation(120.0 * M_PI / 180.0, {3.0, -2.0, 0.0}),
                                 PoseFromYawTranslation(-75.0 * M_PI / 180.0, {-4.0, 1.5, 0.0})}) {
    const ScanPair pair = StreetPair(truth);
    const std::vector<FeatureHypothesis> hypotheses =
        FeatureHypotheses(pair.source.points, pair.source.features, pair.target.points,
                          pair.target.features, StreetOptions(1));
    ASSERT_FALSE(hypotheses.empty());
    ASSERT_LE(hypotheses.size(), 4u);
    const FeatureHypothesis& best = hypotheses.front();
    EXPECT_LT(RotationErrorDegrees(best.transform, truth), 2.0) << best.transform;
    EXPECT_LT(TranslationError(best.transform, truth), 2.0 * kVoxel) << best.transform;
    for (size_t h = 1; h < hypotheses.size(); ++h) {
      EXPECT_LE(hypotheses[h].inliers, hypotheses[h - 1].inliers) << h;
    }
  }
}

TEST(FeatureHypotheses, ExactCorrespondencesGiveTheExactMotion) {
  // Twelve scattered points with distinct made-up descriptors, the target a
  // shuffled moved copy: too few for mutual filtering, so the one-way matches
  // (all right) are used.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coordinate(-10.0, 10.0);
  Points source;
  for (int i = 0; i < 12; ++i)
    source.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  FpfhFeatures source_features(33, 12);
  std::uniform_real_distribution<float> bin(0.0F, 100.0F);
  for (Eigen::Index i = 0; i < source_features.size(); ++i) source_features(i) = bin(rng);
  const Transform truth = PoseFromYawTranslation(2.5, {7.0, -3.0, 0.5});
  const Points moved = TransformPoints(truth, source);
  Points target;
  FpfhFeatures target_features(33, 12);
  for (int i = 0; i < 12; ++i) {
    const int from = (5 * i + 3) % 12;
    target.push_back(moved[static_cast<size_t>(from)]);
    target_features.col(i) = source_features.col(from);
  }
  FeatureMatchOptions options = StreetOptions(1);
  options.iterations = 200;
  const std::vector<FeatureHypothesis> hypotheses =
      FeatureHypotheses(source, source_features, target, target_features, options);
  ASSERT_EQ(hypotheses.size(), 1u);  // wrong triples leave fewer than 3 inliers
  EXPECT_EQ(hypotheses[0].inliers, 12);
  EXPECT_LT(RotationErrorDegrees(hypotheses[0].transform, truth), 1e-4);  // acos near 1
  EXPECT_LT(TranslationError(hypotheses[0].transform, truth), 1e-6);
}

TEST(FeatureHypotheses, SameHypothesesBitForBitWithOneAndTwoThreads) {
  const ScanPair pair = StreetPair(PoseFromYawTranslation(2.0, {2.0, 1.0, 0.0}));
  const auto run = [&](int threads) {
    return FeatureHypotheses(pair.source.points, pair.source.features, pair.target.points,
                             pair.target.features, StreetOptions(threads));
  };
  const std::vector<FeatureHypothesis> serial = run(1);
  const std::vector<FeatureHypothesis> parallel = run(2);
  ASSERT_FALSE(serial.empty());
  ASSERT_EQ(serial.size(), parallel.size());
  for (size_t h = 0; h < serial.size(); ++h) {
    EXPECT_EQ(serial[h].inliers, parallel[h].inliers) << h;
    EXPECT_TRUE(serial[h].transform == parallel[h].transform) << h;  // bit for bit
  }
}

TEST(FeatureHypotheses, EmptyWithoutThreePointsOrWithoutDescriptors) {
  const FeatureMatchOptions options = StreetOptions(1);
  const Points two = {Point(0, 0, 0), Point(1, 0, 0)};
  const FpfhFeatures two_features = FpfhFeatures::Constant(33, 2, 1.0F);
  EXPECT_TRUE(FeatureHypotheses(two, two_features, two, two_features, options).empty());
  EXPECT_TRUE(FeatureHypotheses({}, FpfhFeatures(33, 0), {}, FpfhFeatures(33, 0), options).empty());

  // Points far beyond the radius of one another have no neighbours, so no
  // descriptor: nothing to match.
  Points sparse;
  for (int i = 0; i < 10; ++i) sparse.emplace_back(100.0 * i, 7.0 * (i % 3), 1.0);
  const FpfhFeatures none = Describe(sparse, 1);
  EXPECT_TRUE(none.isZero());
  EXPECT_TRUE(FeatureHypotheses(sparse, none, sparse, none, options).empty());
}

TEST(FeatureHypotheses, InvalidOptionsOrFeatureCountsThrow) {
  const Points three = {Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0)};
  const FpfhFeatures features = FpfhFeatures::Constant(33, 3, 1.0F);
  const auto call = [&](const FeatureMatchOptions& options) {
    return FeatureHypotheses(three, features, three, features, options);
  };
  EXPECT_NO_THROW(call(StreetOptions(1)));
  FeatureMatchOptions bad = StreetOptions(1);
  bad.inlier_distance = 0.0;
  EXPECT_THROW(call(bad), InputError);
  bad = StreetOptions(1);
  bad.inlier_distance = -1.0;
  EXPECT_THROW(call(bad), InputError);
  bad = StreetOptions(1);
  bad.max_hypotheses = 0;
  EXPECT_THROW(call(bad), InputError);
  bad = StreetOptions(1);
  bad.iterations = 0;
  EXPECT_THROW(call(bad), InputError);
  bad = StreetOptions(1);
  bad.distinct_translation = 0.0;
  EXPECT_THROW(call(bad), InputError);
  bad = StreetOptions(1);
  bad.edge_ratio = 1.5;
  EXPECT_THROW(call(bad), InputError);
  EXPECT_THROW(FeatureHypotheses(three, FpfhFeatures(33, 2), three, features, StreetOptions(1)),
               InputError);
}

TEST(FpfhFeatures, RotatingAScanAboutItsSensorKeepsItsDescriptors) {
  const Points scan =
      VoxelDownsample(SimulateScan(MakeSyntheticStreet(5, 15.0),
                                   PoseFromYawTranslation(0.3, {2.0, 1.0, 1.8}), 35.0, 0.02, 3),
                      kVoxel);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(2.2, Eigen::Vector3d(0.3, -0.5, 1.0).normalized()).toRotationMatrix();
  Points rotated;
  for (const Point& p : scan) rotated.push_back(R * p);
  const FpfhFeatures original = Describe(scan, 1);
  const FpfhFeatures turned = Describe(rotated, 1);
  ASSERT_EQ(original.cols(), turned.cols());

  // Rounding may move a pair feature across a bin edge or a neighbour across
  // the radius, so a few descriptors differ by a few units.
  std::vector<float> differences;
  for (Eigen::Index i = 0; i < original.cols(); ++i) {
    differences.push_back((original.col(i) - turned.col(i)).norm());
  }
  std::sort(differences.begin(), differences.end());
  const auto quantile = [&](double q) {
    return differences[static_cast<size_t>(q * static_cast<double>(differences.size() - 1))];
  };
  // The normals themselves differ by rounding, so even an unchanged
  // descriptor is equal only to about 1e-5 of its norm (about 100).
  EXPECT_LT(quantile(0.5), 0.05F);
  EXPECT_LT(quantile(0.95), 1.0F);
}

TEST(FpfhFeatures, BlocksSumTo100AndNeitherNormalSignsNorThreadsMatter) {
  const Points scan =
      VoxelDownsample(SimulateScan(MakeSyntheticStreet(5, 15.0),
                                   PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8}), 35.0, 0.02, 4),
                      kVoxel);
  const NearestNeighborIndex index(scan);
  Points normals = EstimateSurfaceNormals(index, 2.0 * kVoxel, 1);
  const FpfhFeatures features = ComputeFpfhFeatures(index, normals, 5.0 * kVoxel, 1);
  ExpectBlocksSumTo100OrZero(features);
  Eigen::Index described = 0;
  for (Eigen::Index i = 0; i < features.cols(); ++i) described += features.col(i).isZero() ? 0 : 1;
  EXPECT_GT(described, features.cols() * 9 / 10);

  std::mt19937_64 rng(9);
  for (Point& n : normals) {
    if (rng() % 2 == 0) n = -n;
  }
  const FpfhFeatures flipped = ComputeFpfhFeatures(index, normals, 5.0 * kVoxel, 1);
  EXPECT_TRUE(flipped == features);
  EXPECT_TRUE(ComputeFpfhFeatures(index, normals, 5.0 * kVoxel, 2) == features);
}

// A scan moved so its centroid is the origin, as the search levels are, and
// seen from where its sensor now lies, keeps its features: the normals face
// the sensor, not the centroid.
TEST(FpfhFeatures, CentredScansSeenFromTheirSensorKeepTheirFeatures) {
  const Points scan =
      VoxelDownsample(SimulateScan(MakeSyntheticStreet(5, 15.0),
                                   PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8}), 35.0, 0.02, 4),
                      kVoxel);
  Point centre = Point::Zero();
  for (const Point& p : scan) centre += p;
  centre /= static_cast<double>(scan.size());
  Points centred = scan;
  for (Point& p : centred) p -= centre;
  const NearestNeighborIndex index(scan), centred_index(centred);
  const Points normals = EstimateSurfaceNormals(index, 2.0 * kVoxel, 1);
  const FpfhFeatures features = ComputeFpfhFeatures(index, normals, 5.0 * kVoxel, 1);
  const FpfhFeatures seen_from_sensor = ComputeFpfhFeatures(centred_index, normals, 5.0 * kVoxel, 1,
                                                            kMaxFpfhNeighbours, Point(-centre));
  const FpfhFeatures seen_from_centroid =
      ComputeFpfhFeatures(centred_index, normals, 5.0 * kVoxel, 1);
  const auto share_alike = [&](const FpfhFeatures& other) {
    Eigen::Index alike = 0;
    for (Eigen::Index i = 0; i < features.cols(); ++i) {
      alike += (features.col(i) - other.col(i)).cwiseAbs().maxCoeff() < 1e-3F ? 1 : 0;
    }
    return static_cast<double>(alike) / static_cast<double>(features.cols());
  };
  // Alike up to rounding: a neighbour on the radius can fall either side.
  EXPECT_GT(share_alike(seen_from_sensor), 0.95);
  EXPECT_LT(share_alike(seen_from_centroid), 0.8) << "the test's scan must tell the two apart";
}

TEST(FpfhFeatures, FlatGroundPutsEveryPairInTheMiddleBins) {
  // A grid on the ground 1.8 m below the sensor: parallel normals, every pair
  // feature zero, so each block holds all its mass in bin 5.
  Points ground;
  for (int x = -10; x <= 10; ++x) {
    for (int y = -10; y <= 10; ++y) ground.emplace_back(0.3 * x, 0.3 * y, -1.8);
  }
  const NearestNeighborIndex index(ground);
  const Points normals = EstimateSurfaceNormals(index, 1.0, 1);
  const FpfhFeatures features = ComputeFpfhFeatures(index, normals, 1.0, 1);
  for (Eigen::Index i = 0; i < features.cols(); ++i) {
    for (int block = 0; block < 3; ++block) {
      EXPECT_NEAR(features(11 * block + 5, i), 100.0F, 1e-3F) << "point " << i;
    }
  }
}

TEST(FpfhFeatures, InvalidInputsThrow) {
  const Points points = {Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0)};
  const NearestNeighborIndex index(points);
  const Points normals(3, Point(0, 0, 1));
  EXPECT_THROW(ComputeFpfhFeatures(index, Points(2, Point(0, 0, 1)), 1.0, 1), InputError);
  EXPECT_THROW(ComputeFpfhFeatures(index, normals, 0.0, 1), InputError);
  EXPECT_THROW(ComputeFpfhFeatures(index, normals, 1.0, 1, 0), InputError);
}

}  // namespace
}  // namespace boicp
