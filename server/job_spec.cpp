#include "job_spec.hpp"

#include <cmath>
#include <limits>

#include "boicp/mapping/batch_pair.hpp"
#include "job_limits.hpp"
#include "proto_convert.hpp"

namespace boicp::server {
namespace {

Eigen::Vector3d Bounds(const v1::Vector3& proto, const std::string& field) {
  const Point p = PointFromProto(proto, field);
  if ((p.array() < 0.0).any()) throw InputError(field + ": half-widths must be >= 0");
  return p;
}

std::vector<PairIndex> PairsFromProto(const v1::PairingPolicy& pairing) {
  std::vector<PairIndex> pairs;
  for (const v1::Pair& p : pairing.pairs()) {
    pairs.push_back({static_cast<int>(p.source()), static_cast<int>(p.target())});
  }
  return pairs;
}

}  // namespace

BoIcpConfig ConfigFromProto(const v1::RegistrationConfig& proto, int threads) {
  BoIcpConfig config = PresetConfig(proto.preset().empty() ? "C" : proto.preset());
  if (proto.fixed_settings()) config.automatic.clear();
  config.retry_when_doubtful = !proto.no_retry();
  if (!proto.mode().empty()) config.mode = ParseSearchMode(proto.mode());
  if (proto.has_voxel()) {
    config.voxel = proto.voxel();
    config.MarkSet("voxel");
  }
  if (proto.has_random_samples()) config.random_samples = proto.random_samples();
  if (proto.has_iterations()) config.iterations = proto.iterations();
  if (proto.has_rotation_bounds()) {
    config.rotation_bounds =
        SnapRotationBounds(Bounds(proto.rotation_bounds(), "config.rotation_bounds"));
    config.MarkSet("rotation_bounds");
  }
  if (proto.has_translation_bounds()) {
    config.translation_bounds = Bounds(proto.translation_bounds(), "config.translation_bounds");
    config.MarkSet("translation_bounds");
  }
  if (proto.has_seed()) config.seed = proto.seed();
  if (proto.has_evaluation_points()) config.evaluation_points = proto.evaluation_points();
  if (proto.has_refine_voxel()) {
    config.refine_voxel = proto.refine_voxel();
    config.MarkSet("refine_voxel");
  }
  if (proto.has_max_correspondence()) {
    config.max_correspondence_distance = proto.max_correspondence();
  }
  if (proto.has_min_range()) config.min_range = proto.min_range();
  if (proto.has_max_range()) config.max_range = proto.max_range();
  config.threads = threads;
  try {
    ValidateConfig(config);
  } catch (const InputError& e) {
    throw InputError(std::string("config: ") + e.what());
  }
  return config;
}

MapBuildSettings MapSettingsFromProto(const v1::MapSettings& proto) {
  MapBuildSettings settings;
  OccupancySettings& o = settings.occupancy;
  if (proto.has_resolution()) o.resolution = proto.resolution();
  if (proto.has_max_range()) o.max_range = proto.max_range();
  const v1::SensorModel& model = proto.sensor_model();
  if (model.prob_hit() != 0.0) o.prob_hit = model.prob_hit();
  if (model.prob_miss() != 0.0) o.prob_miss = model.prob_miss();
  if (model.clamp_min() != 0.0) o.clamp_min = model.clamp_min();
  if (model.clamp_max() != 0.0) o.clamp_max = model.clamp_max();
  ValidateOccupancySettings(o);
  settings.cloud_voxel = proto.cloud_voxel();
  if (!std::isfinite(settings.cloud_voxel) || settings.cloud_voxel < 0.0) {
    throw InputError("map settings: cloud_voxel must be >= 0 (0 = resolution)");
  }
  return settings;
}

JobSpec BuildJobSpec(const std::string& job_id, const v1::SubmitBatchRequest& request,
                     const std::vector<v1::ScanMetadata>& scans, const DataDir& data_dir,
                     int registration_threads) {
  RequireWithinJobLimits(request);
  JobSpec spec;
  spec.job_id = job_id;
  const int n = request.scan_ids_size();
  if (n < 2) throw InputError("scan_ids: a batch needs at least 2 scans");
  if (static_cast<int>(scans.size()) != n) {
    throw std::runtime_error("job " + job_id + ": scan metadata does not match the batch");
  }
  for (int i = 0; i < n; ++i) {
    const v1::ScanMetadata& meta = scans[static_cast<size_t>(i)];
    const std::string field = "scan_ids[" + std::to_string(i) + "]";
    ScanSource source;
    source.path = data_dir.ScanPath(request.scan_ids(i));
    source.load = LoadOptionsFromMetadata(meta);
    // Stored scans met the point limit at upload; the job checks it at submission.
    source.load.max_points = std::numeric_limits<uint64_t>::max();
    if (meta.has_sensor_origin()) {
      source.sensor_origin = PointFromProto(meta.sensor_origin(), field + ".sensor_origin");
    }
    if (meta.has_prior_pose()) {
      source.prior_pose = TransformFromProto(meta.prior_pose(), field + ".prior_pose");
    }
    if (meta.has_timestamp()) source.timestamp = meta.timestamp();
    spec.scan_ids.push_back(request.scan_ids(i));
    spec.scans.push_back(std::move(source));
  }

  const v1::PairingPolicy& pairing = request.pairing();
  const std::vector<PairIndex> listed = PairsFromProto(pairing);
  switch (pairing.mode()) {
    case v1::PairingPolicy::MODE_UNSPECIFIED:
    case v1::PairingPolicy::MODE_CONSECUTIVE: {
      spec.pairing = PairingMode::kConsecutive;
      spec.base_pairs = ConsecutivePairs(n);
      spec.extra_pairs = listed;
      std::vector<PairIndex> all = spec.base_pairs;
      all.insert(all.end(), listed.begin(), listed.end());
      ValidatePairs(n, all, /*require_connected=*/true);
      break;
    }
    case v1::PairingPolicy::MODE_KEYFRAMES: {
      spec.pairing = PairingMode::kKeyframes;
      const double threshold = pairing.overlap_threshold();
      if (threshold != 0.0 && !(threshold > 0.0 && threshold <= 1.0)) {
        throw InputError("pairing.overlap_threshold must be in (0, 1] (0 = default)");
      }
      spec.overlap_threshold = threshold != 0.0 ? threshold : BatchOverlapThreshold(spec.scans);
      spec.extra_pairs = listed;
      ValidatePairs(n, listed, /*require_connected=*/false);
      break;
    }
    case v1::PairingPolicy::MODE_EXPLICIT:
      spec.pairing = PairingMode::kExplicit;
      if (listed.empty()) throw InputError("pairing.pairs: explicit pairing needs pairs");
      spec.base_pairs = listed;
      ValidatePairs(n, listed, /*require_connected=*/true);
      break;
    default:
      throw InputError("pairing.mode: unknown mode " + std::to_string(pairing.mode()));
  }
  spec.config = ConfigFromProto(request.config(), registration_threads);
  spec.map = MapSettingsFromProto(request.map());
  const bool fixed = request.config().fixed_settings();
  spec.map_auto.resolution = !fixed && !request.map().has_resolution();
  spec.map_auto.max_range = !fixed && !request.map().has_max_range();
  return spec;
}

v1::ChosenSettings ChosenSettingsToProto(const BoIcpConfig& config, const MapBuildSettings& map,
                                         const std::vector<std::string>& auto_fields) {
  v1::ChosenSettings out;
  v1::RegistrationConfig& c = *out.mutable_config();
  c.set_preset(config.preset);
  c.set_mode(SearchModeName(config.mode));
  c.set_voxel(config.voxel);
  c.set_random_samples(config.random_samples);
  c.set_iterations(config.iterations);
  *c.mutable_rotation_bounds() = PointToProto(config.rotation_bounds);
  *c.mutable_translation_bounds() = PointToProto(config.translation_bounds);
  c.set_seed(config.seed);
  c.set_evaluation_points(static_cast<uint32_t>(config.evaluation_points));
  c.set_refine_voxel(config.EffectiveRefineVoxel());
  c.set_max_correspondence(config.EffectiveMaxCorrespondence());
  c.set_min_range(config.min_range);
  c.set_max_range(config.max_range);
  c.set_no_retry(!config.retry_when_doubtful);
  out.set_map_resolution(map.occupancy.resolution);
  out.set_map_max_range(map.occupancy.max_range);
  for (const std::string& field : auto_fields) out.add_auto_fields(field);
  return out;
}

}  // namespace boicp::server
