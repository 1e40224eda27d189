#pragma once
// The settings of the one-shot local map runs behind `boicp map` and
// `boicp merge`: as flags and as the run.json manifest, the scan folder and
// the pairs. Running them is core's map pipeline (local_map.hpp).

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "boicp/io/scan_folder.hpp"
#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/mapping/map_batch.hpp"
#include "boicp/settings/requested_settings.hpp"
#include "local_pairs.hpp"

namespace boicp::cli {

/// Every setting of a map run; what run.json stores. The registration and
/// map settings are the schema's (boicp/settings/setting_schema.hpp); the
/// rest say which scans to read and how to pair them.
struct MapSettings : settings::RequestedSettings {
  std::string path;  // scan folder or bag (made absolute)
  /// Further drives of the same place, each a folder or bag read as `path`
  /// is; mapped into path's first scan's frame (drives.hpp).
  std::vector<std::string> more_paths;
  std::string layout = "auto";
  std::string pairing = "consecutive";  // PairingModeName: consecutive | overlap | explicit
  std::string pairs_file;               // explicit pairing: "source,target" lines
  double overlap_threshold = 0.0;       // overlap pairing; 0 = BatchOverlapThreshold
  std::string extra_pairs_file;         // loop closures besides the pairing's own, same lines
  int first = 0, stride = 1, count = 0;
  std::string intrinsics;  // "fx,fy,cx,cy"
  std::string camera;      // TUM fr1|fr2|fr3
  double depth_scale = 0.0;
  bool poses_as_priors = false;
  BagScanSelection bag;  // when path is a bag
};

nlohmann::json MapSettingsToJson(const MapSettings& settings);
/// Throws InputError naming `source` when a field is missing or mistyped.
MapSettings MapSettingsFromJson(const nlohmann::json& json, const std::string& source);

/// A run resolved from its settings.
struct LocalRun {
  MapSettings settings;
  /// Each drive's folder or bag: settings.path, then more_paths (its scans:
  /// DriveScans(batch.pairing.drive_starts, ...)).
  std::vector<std::string> drive_paths;
  ScanLayout layout = ScanLayout::kAuto;  // the folder's layout (never kAuto)
  std::string description;                // the folder in one line (ScanFolder::description)
  MapBatch batch;                         // one thread per registration
  BatchSettingsChoice chosen;             // what ChooseBatchSettings chose, and from which scans
};

/// Reads the folder and validates everything (config, map settings,
/// pairs). Scans are not loaded. Throws InputError naming the field or file.
LocalRun PrepareRun(const MapSettings& settings);

/// The same for a list of scan files (ReadScanList) in place of
/// settings.path's folder.
LocalRun PrepareRun(const MapSettings& settings, const std::vector<std::string>& files);

/// `settings` with the folder and pairs files as absolute paths (run.json
/// records them so; merge and reruns may start elsewhere).
MapSettings WithAbsolutePaths(MapSettings settings);

/// What `boicp map` does between PrepareRun and the pairs: the settings left
/// automatic chosen from the scans (run.chosen), checked against the scans'
/// extent (RequireVoxelsFitExtent: InputError for a voxel too fine), the
/// fusion memory limit set to `max_fusion_mb` MiB (0 = none; LimitExceeded
/// for a map estimated over it; the scans are profiled on `threads`
/// threads), and fusion set to `threads` threads.
void ChooseMapRunSettings(LocalRun& run, int threads, uint64_t max_fusion_mb);

/// One "settings: ..." line on stderr: the values used and which were chosen.
void PrintRunSettings(const LocalRun& run);

/// run.json: the settings as given, plus "chosen" (the settings used),
/// "auto" (which of them came from the scans), "far_returns" (the points
/// of each measured scan set aside while choosing them) and, when scans were
/// measured, "sensor" ({"type", "why"}: the sensor the settings assumed).
nlohmann::json RunManifestJson(const LocalRun& run);

/// "source,target" index pairs, one a line ('#' comments, blank lines and a
/// "source,target" header skipped). Throws InputError naming file and line.
std::vector<PairIndex> ReadPairsFile(const std::string& path);

/// The stored results of `pairs`, each from the first of `dirs` whose
/// pairs/ holds it, checked against the run's settings. Throws InputError
/// naming the missing pairs or the first file with other settings.
std::map<PairIndex, PairResult> ReadStoredPairs(const LocalRun& run,
                                                const std::vector<PairIndex>& pairs,
                                                const std::vector<std::string>& dirs);

/// OUTDIR/run.json, the settings manifest of a run, shard or merge.
std::string RunManifestPath(const std::string& out_dir);

/// Writes RunManifestJson(run) to OUTDIR/run.json atomically, creating OUTDIR.
void WriteRunManifest(const LocalRun& run, const std::string& out_dir);

/// The settings in DIR/run.json. Throws InputError naming the file when it
/// is missing or malformed.
MapSettings ReadRunManifest(const std::string& dir);

/// Names the settings that differ between two manifests ("seed: 5 vs 6,
/// config: A vs C"); empty when they agree.
std::string ManifestDifferences(const MapSettings& a, const MapSettings& b);

/// Every pair of a fixed plan, its chain then its extras (a shard's share
/// and a merge's pairs are counted in this order).
std::vector<PairIndex> FixedPlanPairs(const PairingPlan& plan);

}  // namespace boicp::cli
