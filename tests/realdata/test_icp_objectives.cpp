// Point-to-plane against point-to-point ICP on every reference pair of the
// shared real data, from starts perturbed by 5 degrees about a random axis
// and one search voxel in a random direction, with the search's ICP
// settings. Both must reach the reference basin (within 2 degrees and one
// voxel) on every pair where point-to-point does, and point-to-plane in fewer
// iterations in all. KITTI and 7-Scenes run at the dataset table's search
// voxel; the bunny at 2.5 mm, about what automatic settings choose: at the
// table's 1 cm its 378 points leave both objectives short of 2 degrees, and
// point-to-point stops sooner there.

#include <cstdio>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "boicp/icp/icp.hpp"
#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/refinement.hpp"
#include "evaluation.hpp"
#include "shared_data.hpp"

namespace boicp {
namespace {

struct ObjectiveCase {
  std::string name;   // folder under ../shared/data
  double voxel;       // metres: the search voxel
  bool depth_images;  // 7-Scenes: 16-bit PNG, 1000 per metre, camera-intrinsics.txt
};

std::ostream& operator<<(std::ostream& os, const ObjectiveCase& c) { return os << c.name; }

class IcpObjectives : public ::testing::TestWithParam<ObjectiveCase> {};

Transform PerturbedStart(const Transform& reference, double voxel, std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  const Eigen::Vector3d offset = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  Transform delta = Transform::Identity();
  delta.topLeftCorner<3, 3>() = Eigen::AngleAxisd(5.0 * M_PI / 180.0, axis).toRotationMatrix();
  delta.topRightCorner<3, 1>() = voxel * offset;
  return delta * reference;
}

TEST_P(IcpObjectives, PointToPlaneReachesTheSameBasinsInFewerIterations) {
  const ObjectiveCase& dataset = GetParam();
  const std::filesystem::path folder = SharedDataFolder(dataset.name);
  if (const std::string missing = MissingSharedData(folder); !missing.empty())
    GTEST_SKIP() << missing;
  const LoadOptions load = SharedDataLoadOptions(folder, dataset.depth_images);
  BoIcpConfig config = PresetConfig("C");
  config.voxel = dataset.voxel;
  config.threads = 2;
  const IcpOptions options = SearchIcpOptions(config);

  std::mt19937_64 rng(20261202);
  int point_reached = 0, plane_reached = 0, plane_missed_where_point_reached = 0;
  int point_iterations = 0, plane_iterations = 0;
  const std::vector<ReferencePair> pairs = ReadPairsCsv((folder / "pairs.csv").string());
  for (const ReferencePair& pair : pairs) {
    // The search clouds and target normals as RegisterPair prepares them.
    const PreparedPair prepared = PreparePair(LoadPointCloud(pair.source, load).points,
                                              LoadPointCloud(pair.target, load).points, config);
    const Points& source = prepared.search_source;
    const NearestNeighborIndex& target = prepared.search_target;
    const Points& normals = prepared.search_target_normals;
    // The clouds are centred, and so is the reference between them.
    const Transform reference =
        CentredTransform(prepared.source_centre, prepared.target_centre, pair.T_target_source);
    const Transform start = PerturbedStart(reference, dataset.voxel, rng);
    const IcpResult point = AlignPointToPoint(source, target, start, options);
    const IcpResult plane = AlignPointToPlane(source, target, normals, start, options);
    const auto reached = [&](const IcpResult& icp) {
      return RotationErrorDeg(icp.transform, reference) < 2.0 &&
             TranslationErrorM(icp.transform, reference) < dataset.voxel;
    };
    point_reached += reached(point);
    plane_reached += reached(plane);
    plane_missed_where_point_reached += reached(point) && !reached(plane);
    point_iterations += point.iterations;
    plane_iterations += plane.iterations;
    std::printf("%-28s point %2d it %6.2f deg %7.4f m   plane %2d it %6.2f deg %7.4f m\n",
                std::filesystem::path(pair.source).filename().c_str(), point.iterations,
                RotationErrorDeg(point.transform, reference),
                TranslationErrorM(point.transform, reference), plane.iterations,
                RotationErrorDeg(plane.transform, reference),
                TranslationErrorM(plane.transform, reference));
  }
  std::printf("%s: point-to-point reached %d/%zu in %d iterations, point-to-plane %d/%zu in %d\n",
              dataset.name.c_str(), point_reached, pairs.size(), point_iterations, plane_reached,
              pairs.size(), plane_iterations);
  EXPECT_EQ(plane_missed_where_point_reached, 0);
  EXPECT_LT(plane_iterations, point_iterations);
}

INSTANTIATE_TEST_SUITE_P(SharedData, IcpObjectives,
                         ::testing::Values(ObjectiveCase{"kitti00", 0.6, false},
                                           ObjectiveCase{"7scenes_redkitchen", 0.05, true},
                                           ObjectiveCase{"bunny", 0.0025, false}),
                         [](const ::testing::TestParamInfo<ObjectiveCase>& info) {
                           return info.param.name;
                         });

}  // namespace
}  // namespace boicp
