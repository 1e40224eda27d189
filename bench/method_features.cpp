// ransac-fpfh and fgr: Open3D's global registration on FPFH features (the
// usual recipe: voxel v, normals within 2v, FPFH within 5v, 1.5v inlier
// distance), followed by the same coarse-to-fine ICP as every other method.

#include <memory>

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/CorrespondenceChecker.h>
#include <open3d/pipelines/registration/FastGlobalRegistration.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/utility/Random.h>

#include "boicp/registration/refinement.hpp"
#include "methods.hpp"

namespace boicp::bench {
namespace {

namespace reg = open3d::pipelines::registration;
using open3d::geometry::KDTreeSearchParamHybrid;
using open3d::geometry::PointCloud;

struct FeatureCloud {
  std::shared_ptr<PointCloud> cloud;
  std::shared_ptr<reg::Feature> fpfh;
};

FeatureCloud ComputeFeatures(const Points& points, double voxel) {
  FeatureCloud out;
  out.cloud = PointCloud(points).VoxelDownSample(voxel);
  if (out.cloud->points_.size() < 3) throw InputError("too few points for FPFH features");
  out.cloud->EstimateNormals(KDTreeSearchParamHybrid(2.0 * voxel, 30));
  out.fpfh = reg::ComputeFPFHFeature(*out.cloud, KDTreeSearchParamHybrid(5.0 * voxel, 100));
  return out;
}

// Open3D's RANSAC draws from one global generator; seed it per pair. With more
// than one thread its iterations interleave, so only a 1-thread run repeats
// bit for bit.
void SeedOpen3d(uint64_t seed) { open3d::utility::random::Seed(static_cast<int>(seed >> 33)); }

RegistrationResult Refined(const Transform& initial, const FeatureCloud& source,
                           const FeatureCloud& target, const Points& raw_source,
                           const Points& raw_target, const BoIcpConfig& config) {
  const PreparedPair pair = PreparePair(raw_source, raw_target, config);
  RegistrationResult output;
  const Transform centred = CentredTransform(pair.source_centre, pair.target_centre, initial);
  output.transform = UncentredTransform(pair.source_centre, pair.target_centre,
                                        RefineCoarseToFine({centred}, pair, config).transform);
  output.evaluations = 1;
  output.source_points = source.cloud->points_.size();
  output.target_points = target.cloud->points_.size();
  output.config = config;
  return output;
}

}  // namespace

RegistrationResult RunRansacFpfh(const Points& raw_source, const Points& raw_target,
                                 const BoIcpConfig& config, bool quick) {
  const double voxel = config.voxel;
  const FeatureCloud source = ComputeFeatures(raw_source, voxel);
  const FeatureCloud target = ComputeFeatures(raw_target, voxel);
  const double distance = 1.5 * voxel;
  const reg::CorrespondenceCheckerBasedOnEdgeLength edge_length(0.9);
  const reg::CorrespondenceCheckerBasedOnDistance close_enough(distance);
  // The smoke test only checks that the method runs, so it caps the iterations.
  const int max_iterations = quick ? 20000 : 100000;
  SeedOpen3d(config.seed);
  const reg::RegistrationResult global = reg::RegistrationRANSACBasedOnFeatureMatching(
      *source.cloud, *target.cloud, *source.fpfh, *target.fpfh, /*mutual_filter=*/true, distance,
      reg::TransformationEstimationPointToPoint(false), 3, {edge_length, close_enough},
      reg::RANSACConvergenceCriteria(max_iterations, 0.999));
  return Refined(global.transformation_, source, target, raw_source, raw_target, config);
}

RegistrationResult RunFastGlobal(const Points& raw_source, const Points& raw_target,
                                 const BoIcpConfig& config) {
  const double voxel = config.voxel;
  const FeatureCloud source = ComputeFeatures(raw_source, voxel);
  const FeatureCloud target = ComputeFeatures(raw_target, voxel);
  SeedOpen3d(config.seed);
  // Absolute scale: the gate is in metres like every other method's, not a
  // fraction of the cloud's diameter.
  const reg::FastGlobalRegistrationOption option(1.4, /*use_absolute_scale=*/true, true,
                                                 1.5 * voxel, 64, 0.95, 1000, true);
  const reg::RegistrationResult global = reg::FastGlobalRegistrationBasedOnFeatureMatching(
      *source.cloud, *target.cloud, *source.fpfh, *target.fpfh, option);
  return Refined(global.transformation_, source, target, raw_source, raw_target, config);
}

}  // namespace boicp::bench
