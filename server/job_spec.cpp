#include "job_spec.hpp"

#include <cmath>
#include <limits>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "boicp/rpc/settings_proto.hpp"
#include "boicp/settings/requested_settings.hpp"
#include "job_limits.hpp"

namespace boicp::server {

BoIcpConfig ConfigFromProto(const v1::RegistrationConfig& proto, int threads) {
  try {
    BoIcpConfig config = settings::ConfigFromSettings(rpc::SettingsFromProto(proto, {}));
    config.threads = threads;
    return config;
  } catch (const InputError& e) {
    const std::string message = e.what();
    // SettingsFromProto already names the field ("config.voxel: ...").
    if (message.rfind("config.", 0) == 0) throw;
    throw InputError("config: " + message);
  }
}

MapBuildSettings MapSettingsFromProto(const v1::MapSettings& proto) {
  return settings::MapBuildFromSettings(rpc::SettingsFromProto({}, proto));
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
    source.load = rpc::LoadOptionsFromMetadata(meta);
    // Stored scans met the point limit at upload; the job checks it at submission.
    source.load.max_points = std::numeric_limits<uint64_t>::max();
    if (meta.has_sensor_origin()) {
      source.sensor_origin = rpc::PointFromProto(meta.sensor_origin(), field + ".sensor_origin");
    }
    if (meta.has_prior_pose()) {
      source.prior_pose = rpc::TransformFromProto(meta.prior_pose(), field + ".prior_pose");
    }
    if (meta.has_timestamp()) source.timestamp = meta.timestamp();
    spec.scan_ids.push_back(request.scan_ids(i));
    spec.scans.push_back(std::move(source));
  }

  spec.config = ConfigFromProto(request.config(), registration_threads);
  const PairingRequest pairing = rpc::PairingFromProto(request.pairing());
  spec.pairing = pairing.mode;
  spec.plan = PlanPairing(pairing, spec.scans, spec.config.sensor);
  spec.map = MapSettingsFromProto(request.map());
  spec.map_auto =
      settings::MapAutoFromSettings(rpc::SettingsFromProto(request.config(), request.map()));
  return spec;
}

v1::ChosenSettings ChosenSettingsToProto(const BoIcpConfig& config, const MapBuildSettings& map,
                                         const BatchSettingsChoice& choice) {
  v1::ChosenSettings out;
  *out.mutable_config() = rpc::RegistrationConfigToProto(settings::SettingsFromConfig(config));
  out.set_map_resolution(map.occupancy.resolution);
  out.set_map_max_range(map.occupancy.max_range);
  for (const std::string& field : choice.fields) out.add_auto_fields(field);
  uint64_t far_returns = 0;
  for (const MeasuredScan& m : choice.measured) far_returns += m.far_returns;
  out.set_far_returns(far_returns);
  if (!choice.measured.empty()) {
    out.set_sensor(SensorKindName(choice.sensor));
    out.set_sensor_why(choice.sensor_reason);
  }
  return out;
}

}  // namespace boicp::server
