// Config C on every reference pair of the shared real data, from a seeded
// random rotation of the source, so the truth is far from identity. Success
// per pair: rotation and translation error under the dataset's tolerance; the
// dataset passes when at least 95 % of its pairs succeed.

#include <cstdio>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "boicp/bo_icp.hpp"
#include "boicp/evaluation.hpp"
#include "boicp/point_cloud_io.hpp"

namespace boicp {
namespace {

struct DatasetCase {
  std::string name;  // folder under ../shared/data
  PerturbationKind perturbation;
  double max_rotation_deg;
  double max_translation_m;
  double voxel;         // search voxel for this sensor's scale (config C's 0.6 m is for LiDAR)
  double refine_voxel;  // finest refinement level; 0 = voxel / 4
  Eigen::Vector3d rotation_bounds;  // ground vehicles: small roll and pitch
  Eigen::Vector3d translation_bounds;
  bool depth_images;  // 7-Scenes: 16-bit PNG, 1000 per metre, camera-intrinsics.txt
};

std::ostream& operator<<(std::ostream& os, const DatasetCase& c) { return os << c.name; }

// Roll and pitch of a car stay within a few degrees; yaw is unknown.
const Eigen::Vector3d kGroundVehicle(0.2, 0.2, M_PI);
const Eigen::Vector3d kAnyRotation(M_PI, M_PI / 2, M_PI);

class RealPairs : public ::testing::TestWithParam<DatasetCase> {};

TEST_P(RealPairs, ConfigCRecoversPerturbedReference) {
  const DatasetCase& dataset = GetParam();
  const std::filesystem::path folder = std::filesystem::path(BOICP_SHARED_DATA_DIR) / dataset.name;
  if (!std::filesystem::exists(folder / "pairs.csv")) {
    GTEST_SKIP() << "real data not found at " << folder.string()
                 << " (../shared/data beside the project root); skipping";
  }
  LoadOptions load;
  if (dataset.depth_images) {
    load.depth.intrinsics = ReadIntrinsicsFile((folder / "camera-intrinsics.txt").string());
    load.depth.depth_scale = 1000.0;
  }
  BoIcpConfig config = PresetConfig("C");
  config.voxel = dataset.voxel;
  config.refine_voxel = dataset.refine_voxel;
  config.rotation_bounds = dataset.rotation_bounds;
  config.translation_bounds = dataset.translation_bounds;
  config.threads = 1;

  const std::vector<ReferencePair> pairs = ReadPairsCsv((folder / "pairs.csv").string());
  std::mt19937_64 rng(20261122);
  int successes = 0;
  std::vector<double> runtimes;
  std::printf("%-36s %-36s %9s %9s %8s %6s %5s\n", "source", "target", "rot_deg", "trans_m",
              "time_s", "conf", "ok");
  for (const ReferencePair& pair : pairs) {
    const Transform perturbation = RandomPerturbation(dataset.perturbation, rng);
    const Points source = TransformPoints(perturbation, LoadPointCloud(pair.source, load).points);
    const Points target = LoadPointCloud(pair.target, load).points;
    const Transform expected = pair.T_target_source * perturbation.inverse();
    config.seed = rng();
    const RegistrationResult result = RegisterPair(source, target, config);
    const double rot = RotationErrorDeg(result.transform, expected);
    const double trans = TranslationErrorM(result.transform, expected);
    const bool ok = rot < dataset.max_rotation_deg && trans < dataset.max_translation_m;
    successes += ok;
    runtimes.push_back(result.runtime_s);
    std::printf("%-36s %-36s %9.3f %9.4f %8.2f %6.3f %5s\n",
                std::filesystem::path(pair.source).filename().c_str(),
                std::filesystem::path(pair.target).filename().c_str(), rot, trans, result.runtime_s,
                result.confidence, ok ? "yes" : "NO");
    std::fflush(stdout);
  }
  std::sort(runtimes.begin(), runtimes.end());
  std::printf("%s: %d/%zu pairs within %.1f deg and %.3f m; median runtime %.2f s\n",
              dataset.name.c_str(), successes, pairs.size(), dataset.max_rotation_deg,
              dataset.max_translation_m, runtimes[runtimes.size() / 2]);
  EXPECT_GE(successes, static_cast<int>(std::ceil(0.95 * static_cast<double>(pairs.size()))));
}

// Per-sensor settings a user would choose: the voxel follows the scene's scale
// (config C's 0.6 m is for street LiDAR), the bounds follow the platform.
std::vector<DatasetCase> Datasets() {
  DatasetCase kitti{"kitti00",      PerturbationKind::kYaw,         2.0,  0.3, 0.6, 0.0,
                    kGroundVehicle, Eigen::Vector3d(4.0, 2.0, 1.0), false};
  DatasetCase scenes{"7scenes_redkitchen", PerturbationKind::kAxis90,      2.0, 0.05, 0.05, 0.0,
                     kAnyRotation,         Eigen::Vector3d(1.0, 1.0, 1.0), true};
  DatasetCase bunny{"bunny",      PerturbationKind::kAxis90,      2.0,  0.005, 0.01, 0.001,
                    kAnyRotation, Eigen::Vector3d(0.1, 0.1, 0.1), false};
  return {kitti, scenes, bunny};
}

INSTANTIATE_TEST_SUITE_P(SharedData, RealPairs, ::testing::ValuesIn(Datasets()),
                         [](const ::testing::TestParamInfo<DatasetCase>& info) {
                           std::string name = info.param.name;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace boicp
