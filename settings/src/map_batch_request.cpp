#include "boicp/settings/map_batch_request.hpp"

#include <utility>

namespace boicp::settings {
namespace {

// Names the group of settings an error is about, unless it already names
// the group ("map settings: ...") or a field in it ("config.voxel: ...").
InputError InGroup(const std::string& group, const InputError& e) {
  const std::string message = e.what();
  const char after = message.size() > group.size() ? message[group.size()] : '\0';
  if (message.rfind(group, 0) == 0 && (after == ':' || after == '.')) return e;
  return InputError(group + ": " + message);
}

}  // namespace

MapBatch MakeMapBatch(std::vector<ScanSource> scans, const RequestedSettings& requested,
                      PairingRequest pairing, int registration_threads,
                      const std::string& pairs_source) {
  MapBatch batch;
  try {
    batch.config = ConfigFromSettings(requested);
  } catch (const InputError& e) {
    throw InGroup("config", e);
  }
  batch.config.threads = registration_threads;
  // Unset map settings keep OccupancySettings' fixed defaults until
  // ChooseBatchSettings replaces those left automatic.
  try {
    batch.map = MapBuildFromSettings(requested);
  } catch (const InputError& e) {
    throw InGroup("map settings", e);
  }
  batch.map_auto = MapAutoFromSettings(requested);
  batch.scans = std::move(scans);
  batch.plan = PlanPairing(pairing, batch.scans, batch.config.sensor, pairs_source);
  batch.pairing = std::move(pairing);
  return batch;
}

}  // namespace boicp::settings
