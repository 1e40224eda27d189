#pragma once
// How a batch's pairs are asked for, in one vocabulary for `boicp map`,
// run.json and the API, and the one function that turns a request into a
// plan for both the daemon and `boicp map`.

#include <optional>
#include <string>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/map_pairs.hpp"

namespace boicp {

enum class PairingMode {
  kConsecutive,  ///< each scan onto the next
  kOverlap,      ///< keyframes chosen by overlap (KeyframePlanner)
  kExplicit,     ///< the listed pairs only
};

/// "consecutive", "overlap" or "explicit".
std::string PairingModeName(PairingMode mode);

/// The mode a name gives, or nullopt.
std::optional<PairingMode> PairingModeFromName(const std::string& name);

struct PairingRequest {
  PairingMode mode = PairingMode::kConsecutive;
  /// kOverlap: a scan whose overlap with the current keyframe falls under
  /// this starts the next keyframe, in (0, 1]; 0 = the batch's default
  /// (BatchOverlapThreshold).
  double overlap_threshold = 0.0;
  /// kExplicit: every pair the batch registers. The other modes: pairs
  /// registered besides their own (loop closures), which the pose graph
  /// weighs against the chain.
  std::vector<PairIndex> pairs;
  /// Several drives of one place (consecutive pairing only): the first scan
  /// of each drive after the first, ascending (drives.hpp). Empty: one drive.
  std::vector<int> drive_starts;
};

/// The keyframe overlap threshold of a batch: that of the `sensor` the user
/// set, else 0.6 when every scan is a depth image and 0.7 otherwise.
double BatchOverlapThreshold(const std::vector<ScanSource>& scans,
                             const std::optional<SensorKind>& sensor);

/// The plan of `request` for `scans` (at least 2) whose sensor the user set
/// to `sensor` (nullopt: auto). Throws InputError for a pair outside the
/// scans, a scan paired with itself or twice, pairs that leave a scan
/// unreached (consecutive and explicit: the plan must connect every scan of
/// one drive; several drives are joined later, by the pairs the map finds)
/// or explicit pairing without pairs, naming `pairs_source` (where the pairs
/// came from: the API's field, or a file); for a threshold outside (0, 1],
/// naming "pairing.overlap_threshold"; and for drive starts with another
/// mode than consecutive, or a drive of fewer than 2 scans.
PairingPlan PlanPairing(const PairingRequest& request, const std::vector<ScanSource>& scans,
                        const std::optional<SensorKind>& sensor,
                        const std::string& pairs_source = "pairing.pairs");

}  // namespace boicp
