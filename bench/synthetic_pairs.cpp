#include <cmath>

#include "bench_pairs.hpp"
#include "boicp/io/synthetic_scene.hpp"

namespace boicp::bench {
namespace {

// Sensor poses along the generated street, 1.8 m up like a car roof scanner.
Transform StreetPose(size_t index) {
  return PoseFromYawTranslation(0.05 * static_cast<double>(index),
                                {1.5 * static_cast<double>(index), 0.3, 1.8});
}

constexpr uint64_t kStreetSeed = 11;
constexpr double kStreetDensity = 15.0;  // points per square metre: KITTI-like after a 0.6 m voxel
constexpr double kScanRange = 30.0;
constexpr double kScanNoise = 0.01;

}  // namespace

DatasetPairs SyntheticDataset(int count, const DatasetOverrides& overrides) {
  DatasetPairs dataset;
  dataset.settings = SettingsForDataset("synthetic", overrides);
  dataset.folder = "synthetic";
  for (int i = 0; i < count; ++i) {
    ReferencePair reference;
    reference.source = "synthetic/scan_" + std::to_string(i + 1);
    reference.target = "synthetic/scan_" + std::to_string(i);
    reference.T_target_source = StreetPose(i).inverse() * StreetPose(i + 1);
    dataset.references.push_back(reference);
  }
  return dataset;
}

BenchPair MakeSyntheticPair(const DatasetPairs& dataset, size_t index, uint64_t seed) {
  const Points world = MakeSyntheticStreet(kStreetSeed, kStreetDensity);
  return PerturbPair(
      dataset, index, seed,
      SimulateScan(world, StreetPose(index + 1), kScanRange, kScanNoise, 2 * index + 1),
      SimulateScan(world, StreetPose(index), kScanRange, kScanNoise, 2 * index + 2));
}

}  // namespace boicp::bench
