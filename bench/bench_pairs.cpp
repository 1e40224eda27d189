#include "bench_pairs.hpp"

#include <cmath>
#include <filesystem>
#include <utility>

#include "boicp/io/point_cloud_io.hpp"
#include "seeds.hpp"

namespace boicp::bench {
namespace {

std::string RelativeName(const std::string& path, const std::string& folder) {
  return std::filesystem::path(path).lexically_relative(folder).generic_string();
}

constexpr uint64_t kFieldSalt = 0x8ebc6af09c88c6e3ULL;

uint64_t PairSeed(const DatasetPairs& dataset, size_t index, uint64_t seed) {
  return MixSeed(MixSeed(seed, NameSeed(dataset.settings.name)), index);
}

}  // namespace

Transform DrawPerturbation(const DatasetSettings& settings, std::mt19937_64& rng) {
  Transform P = Transform::Identity();
  if (settings.perturb == PerturbationKind::kYaw) {
    std::uniform_real_distribution<double> angle(-M_PI, M_PI);
    P.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  } else if (settings.perturb == PerturbationKind::kAxis90) {
    std::normal_distribution<double> gauss(0.0, 1.0);
    Eigen::Vector3d axis(gauss(rng), gauss(rng), gauss(rng));
    axis.normalize();
    std::uniform_real_distribution<double> angle(0.0, settings.max_angle_deg * M_PI / 180.0);
    P.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle(rng), axis).toRotationMatrix();
  }
  if (settings.perturb != PerturbationKind::kNone) {
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int k = 0; k < 3; ++k) P(k, 3) = unit(rng) * settings.translation_bounds[k];
  }
  return P;
}

BenchPair PerturbPair(const DatasetPairs& dataset, size_t index, uint64_t seed, Points source,
                      Points target) {
  std::mt19937_64 rng(PairSeed(dataset, index, seed));
  BenchPair pair;
  pair.dataset = dataset.settings.name;
  const ReferencePair& reference = dataset.references[index];
  pair.source_name = RelativeName(reference.source, dataset.folder);
  pair.target_name = RelativeName(reference.target, dataset.folder);
  pair.perturbation = DrawPerturbation(dataset.settings, rng);
  pair.source = TransformPoints(pair.perturbation, source);
  pair.target = std::move(target);
  pair.expected = reference.T_target_source * pair.perturbation.inverse();
  pair.method_seed = rng();
  return pair;
}

DatasetPairs ReadDataset(const std::string& pairs_csv, const DatasetOverrides& overrides) {
  DatasetPairs dataset;
  dataset.references = ReadPairsCsv(pairs_csv);
  const std::filesystem::path folder = std::filesystem::path(pairs_csv).parent_path();
  dataset.folder = folder.string();
  dataset.settings = SettingsForDataset(folder.filename().string(), overrides);
  return dataset;
}

BenchPair LoadPair(const DatasetPairs& dataset, size_t index, uint64_t seed) {
  LoadOptions load;
  if (dataset.settings.depth_scale > 0.0) {
    load.depth.intrinsics = ReadIntrinsicsFile(
        (std::filesystem::path(dataset.folder) / dataset.settings.intrinsics_file).string());
    load.depth.depth_scale = dataset.settings.depth_scale;
  }
  const ReferencePair& reference = dataset.references.at(index);
  FieldPair field = ApplyFieldCondition(
      dataset.settings.field, LoadPointCloud(reference.source, load).points,
      LoadPointCloud(reference.target, load).points, PairSeed(dataset, index, seed) ^ kFieldSalt);
  BenchPair pair =
      PerturbPair(dataset, index, seed, std::move(field.source), std::move(field.target));
  pair.expected = field.Expected(reference.T_target_source, pair.perturbation);
  pair.error_point = field.ErrorPoint(pair.perturbation);
  return pair;
}

}  // namespace boicp::bench
