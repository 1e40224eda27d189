#include "boicp/mapping/batch_pair.hpp"

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <optional>
#include <sstream>

namespace boicp {

PairResult RegisterBatchPair(const std::vector<ScanSource>& scans, const PairIndex& pair,
                             const BoIcpConfig& job_config, PreparedScanCache& prepared,
                             const std::function<bool()>& stop_requested,
                             const std::optional<Transform>& prior) {
  const std::shared_ptr<const PreparedScan> source = prepared.Get(pair.source);
  const std::shared_ptr<const PreparedScan> target = prepared.Get(pair.target);

  BoIcpConfig config = job_config;
  config.seed = PairSeed(job_config.seed, pair);
  RegistrationCallbacks callbacks;
  callbacks.stop_requested = stop_requested;
  PairHints hints;
  hints.prior = prior ? prior
                      : PairPrior(scans[static_cast<size_t>(pair.source)],
                                  scans[static_cast<size_t>(pair.target)]);
  // Scans next to each other in a batch are usually a drive's consecutive
  // scans, which ICP from identity aligns: the ladder's prior rung tries it.
  if (std::abs(pair.source - pair.target) == 1) hints.guess = Transform::Identity();
  const RegistrationResult registration =
      CoreMethods().Create(config.method, config)->Register(*source, *target, hints, callbacks);
  return MakePairResult(pair, registration, config.seed);
}

BatchSettingsChoice ApplyBatchSettings(const std::vector<ScanSource>& scans, BoIcpConfig& config,
                                       OccupancySettings& occupancy,
                                       const MapAutoFields& map_auto) {
  if (scans.empty()) throw InputError("a batch needs at least one scan");
  if (config.automatic.empty() && !map_auto.resolution && !map_auto.max_range) return {};
  constexpr size_t kSampledScans = 5;
  const size_t count = std::min(kSampledScans, scans.size());
  BatchSettingsChoice choice;
  std::vector<Points> clouds;
  CloudFormat format = CloudFormat::kAuto;
  for (size_t k = 0; k < count; ++k) {
    const size_t index = count == 1 ? 0 : k * (scans.size() - 1) / (count - 1);
    LoadedCloud loaded = LoadPointCloud(scans[index].path, scans[index].load);
    format = loaded.format;
    clouds.push_back(std::move(loaded.points));
    choice.measured.push_back({index, 0});
  }
  // Every loaded cloud is measured, in order (max_clouds = their number).
  const ChosenSettings chosen = ChooseSettingsForClouds(
      {clouds.begin(), clouds.end()}, DeclareSensor(config.sensor, format), config.seed, count);
  for (size_t k = 0; k < count; ++k) choice.measured[k].far_returns = chosen.far_returns[k];
  choice.sensor = chosen.sensor;
  choice.sensor_reason = chosen.sensor_reason;
  choice.fields = ApplyChosenSettings(chosen, config);
  if (map_auto.resolution) {
    occupancy.resolution = chosen.map_resolution;
    choice.fields.push_back("map_resolution");
  }
  if (map_auto.max_range) {
    occupancy.max_range = chosen.map_max_range;
    choice.fields.push_back("map_max_range");
  }
  return choice;
}

std::string DoubtfulSummary(int doubtful, int total) {
  return std::to_string(doubtful) + " of " + std::to_string(total) + " pairs doubtful";
}

PoseGraphOptions BatchPoseGraphOptions(const BoIcpConfig& job_config) {
  PoseGraphOptions options;
  options.max_correspondence_distance = job_config.EffectiveInlierDistance();
  options.pair_error = kPairErrorOfInlierDistance * options.max_correspondence_distance;
  return options;
}

void RequireVoxelsFitExtent(const BoIcpConfig& config, double extent) {
  const double floor = kMinVoxelOfExtent * extent;
  const auto require = [&](const char* field, double voxel) {
    if (voxel >= floor) return;
    std::ostringstream message;
    message << field << ": " << voxel << " m is finer than " << kMinVoxelOfExtent
            << " of the scans' extent (" << extent << " m); use at least " << floor << " m";
    throw InputError(message.str());
  };
  require("voxel", config.voxel);
  require("refine_voxel", config.EffectiveRefineVoxel());
}

}  // namespace boicp
