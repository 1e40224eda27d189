#include "job_spec.hpp"

#include <cmath>
#include <limits>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "boicp/rpc/settings_proto.hpp"
#include "boicp/settings/map_batch_request.hpp"
#include "boicp/settings/requested_settings.hpp"
#include "job_limits.hpp"

namespace boicp::server {
namespace {

// Where a scan was taken, from a message that says it (ScanMetadata or
// ScanContext, whose fields share their names); unset fields mean none.
template <typename Context>
void ApplyContextFields(const Context& context, const std::string& field, ScanSource& source) {
  if (context.has_sensor_origin()) {
    source.sensor_origin = rpc::PointFromProto(context.sensor_origin(), field + ".sensor_origin");
  }
  if (context.has_prior_pose()) {
    source.prior_pose = rpc::TransformFromProto(context.prior_pose(), field + ".prior_pose");
  }
  if (context.has_timestamp()) {
    if (!std::isfinite(context.timestamp())) {
      throw InputError(field + ".timestamp: non-finite value");
    }
    source.timestamp = context.timestamp();
  }
}

// The scan's context in the batch: the request's scan_context[i] when the
// batch sends one, else the context its first upload stored.
void ApplyScanContext(const v1::SubmitBatchRequest& request, int i, const v1::ScanMetadata& meta,
                      ScanSource& source) {
  if (request.scan_context_size() == 0) {
    ApplyContextFields(meta, "scan_ids[" + std::to_string(i) + "]", source);
  } else {
    ApplyContextFields(request.scan_context(i), "scan_context[" + std::to_string(i) + "]", source);
  }
}

}  // namespace

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
  // One context per scan or none: the count is bounded by scan_ids'
  // (--max-batch-scans) and the request by --max-message-bytes.
  if (request.scan_context_size() != 0 && request.scan_context_size() != n) {
    throw InputError("scan_context: " + std::to_string(request.scan_context_size()) +
                     " entries for " + std::to_string(n) +
                     " scan_ids; send one per scan, in the same order, or none (each scan's "
                     "context as its first upload stored it)");
  }
  std::vector<ScanSource> sources;
  for (int i = 0; i < n; ++i) {
    const v1::ScanMetadata& meta = scans[static_cast<size_t>(i)];
    ScanSource source;
    source.path = data_dir.ScanPath(request.scan_ids(i));
    source.load = rpc::LoadOptionsFromMetadata(meta);
    // Stored scans met the point limit at upload; the job checks it at submission.
    source.load.max_points = std::numeric_limits<uint64_t>::max();
    ApplyScanContext(request, i, meta, source);
    spec.scan_ids.push_back(request.scan_ids(i));
    sources.push_back(std::move(source));
  }
  spec.batch = settings::MakeMapBatch(
      std::move(sources), rpc::SettingsFromProto(request.config(), request.map()),
      rpc::PairingFromProto(request.pairing()), registration_threads);
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
