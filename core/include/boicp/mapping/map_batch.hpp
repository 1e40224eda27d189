#pragma once
// One batch to map, as the daemon and `boicp map` both describe it: its
// scans, how they pair, and its settings. settings::MakeMapBatch builds it
// from any front end's request (flags, run.json, a SubmitBatchRequest).

#include <vector>

#include "boicp/io/scan_source.hpp"
#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/batch_pairing.hpp"
#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/pair_scale.hpp"
#include "boicp/registration/config.hpp"

namespace boicp {

struct MapBatch {
  std::vector<ScanSource> scans;  // at least 2
  PairingRequest pairing;         // as asked, pairs read from their files
  PairingPlan plan;               // PlanPairing(pairing, scans, config.sensor)
  BoIcpConfig config;             // config.seed is the batch seed
  MapBuildSettings map;
  MapAutoFields map_auto;  // map settings still to be chosen from the scans
  BatchScale scale;        // how each pair scales the settings (ChooseBatchSettings)
};

/// Chooses, once for the batch, what its settings leave automatic
/// (ApplyBatchSettings) and validates the result; afterwards nothing is
/// automatic. Sets batch.scale from `profiles` (ProfileRanges of each scan,
/// in order; an empty one for a scan without), so that pairs far from the
/// measured scans' scale get scaled settings. Throws InputError when a scan
/// does not load or the chosen settings are invalid.
BatchSettingsChoice ChooseBatchSettings(MapBatch& batch, const std::vector<RangeProfile>& profiles);

}  // namespace boicp
