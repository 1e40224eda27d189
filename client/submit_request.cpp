#include "submit_request.hpp"

#include "boicp/rpc/proto_convert.hpp"
#include "boicp/rpc/settings_proto.hpp"

namespace boicp::cli {

v1::SubmitBatchRequest BuildSubmitRequest(const LocalRun& run, const std::string& label) {
  const MapSettings& s = run.settings;
  v1::SubmitBatchRequest request;
  *request.mutable_pairing() = rpc::PairingToProto(run.batch.pairing);
  *request.mutable_config() = rpc::RegistrationConfigToProto(s);
  *request.mutable_map() = rpc::MapSettingsToProto(s);
  if (s.fixed_settings) {
    // The fixed map settings, as this client validated them.
    request.mutable_map()->set_resolution(run.batch.map.occupancy.resolution);
    request.mutable_map()->set_max_range(run.batch.map.occupancy.max_range);
  }
  request.set_label(label.empty() ? s.path : label);
  // The daemon keeps a scan's first upload's context as a default only, so a
  // second submit of the same scans with other priors or times uses its own.
  for (const ScanSource& scan : run.batch.scans) {
    *request.add_scan_context() = rpc::ScanContextOf(scan);
  }
  return request;
}

}  // namespace boicp::cli
