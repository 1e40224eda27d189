#pragma once
// The one function that turns a batch request, from any front end, into the
// batch the map pipeline runs: `boicp map` and `submit` (flags, run.json)
// and the daemon (a SubmitBatchRequest, through rpc::SettingsFromProto and
// rpc::PairingFromProto) all build their batch here.

#include <string>
#include <vector>

#include "boicp/mapping/map_batch.hpp"
#include "boicp/settings/requested_settings.hpp"

namespace boicp::settings {

/// The batch of `scans` (at least 2) with the settings `requested` (the
/// preset filling what is unset; what is automatic stays so until
/// ChooseBatchSettings) and `pairing`, planned. `registration_threads` is
/// the threads inside one registration (config.threads); `pairs_source`
/// names where pairing.pairs came from (the API's field, or a file). Throws
/// InputError: "config: ..." or "map settings: ..." for an invalid setting,
/// PlanPairing's errors for the pairing.
MapBatch MakeMapBatch(std::vector<ScanSource> scans, const RequestedSettings& requested,
                      PairingRequest pairing, int registration_threads,
                      const std::string& pairs_source = "pairing.pairs");

}  // namespace boicp::settings
