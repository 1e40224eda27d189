#pragma once
// One registered pair of a scan batch: what the map pipeline stores, plans
// and assembles with, and what pair files, pairs.json, the daemon's results
// and `boicp show` carry. Its fields are listed once, in PairResultFields();
// the JSON (settings/pair_result_json) and proto (rpc/pair_result_proto)
// conversions are generated from that list, so a field added here reaches
// every format at once.

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "boicp/mapping/map_pairs.hpp"
#include "boicp/mapping/pose_graph.hpp"
#include "boicp/registration/bo_icp.hpp"

namespace boicp {

/// Frame convention: `transform` is T_target_source (metres, radians).
struct PairResult {
  PairIndex pair;  // the result's key: "source" and "target" in every format
  Transform transform = Transform::Identity();
  double objective = 0.0;    // RegistrationResult::objective, metres
  double fitness = 0.0;      // RegistrationResult::fitness
  double inlier_rmse = 0.0;  // metres
  /// RegistrationResult::confidence in [0, 1], and the pair's pose-graph
  /// weight. Results stored before confidence was calibrated read as 1 and
  /// not doubtful: fully trusted, as they were then.
  double confidence = 1.0;
  bool doubtful = false;  // confidence < kTrustedFrom
  /// RegistrationResult::overlap; unknown in results stored before it was computed.
  std::optional<double> overlap;
  /// RegistrationResult::search_reach; unknown in results stored before it was computed.
  std::optional<double> search_reach;
  /// The rung whose answer was kept; results stored before it was recorded
  /// read as the full search, which every answer then was.
  Rung answered_by = Rung::kFullSearch;
  int evaluations = 0;  // ICP runs of every rung together
  double runtime_s = 0.0;
  uint64_t seed = 0;  // the pair's own seed, PairSeed(job seed, pair)
  /// How firmly the inliers pin down `transform` (RegistrationResult::information).
  InformationMatrix information = InformationMatrix::Identity();
  /// RegistrationResult::unconstrained; unknown in results stored before it was measured.
  std::optional<std::vector<FreeSlide>> unconstrained;
  /// False for a keyframe probe or loop closure the final poses leave out.
  bool in_graph = true;
  /// Why the pair was registered: "chain" (the plan's own pairs, keyframe
  /// probes included), "extra" (listed by the user), "bridge" (joins the
  /// scans around a doubtful chain pair) or "loop" (a loop candidate the map
  /// found itself).
  std::string kind = "chain";
  /// For a loop: how its candidate was found, "poses" (its scans' views lie
  /// within reach under the chained poses); empty for the other kinds.
  std::string found_by;
  /// Why the final poses leave the pair out; empty when in_graph (and for
  /// keyframe probes the chain did not need).
  std::string left_out_because;
  double finished_at = 0.0;  // Unix seconds; 0 when not recorded
};

/// The pair result of one registration.
PairResult MakePairResult(const PairIndex& pair, const RegistrationResult& registration,
                          uint64_t seed);

/// What the keyframe planner reads of a finished pair: its overlap (the
/// fitness for results stored before overlap was computed), its reach (0
/// when unknown) and whether it is doubtful.
KeyframePlanner::ProbeOutcome ProbeOutcomeOf(const PairResult& result);

/// The pose-graph edge of a finished pair, weighted by its confidence.
PairConstraint ConstraintOf(const PairResult& result);

/// The formats a field of PairResult appears in, as bits.
enum PairResultFormat : unsigned {
  kPairFile = 1u << 0,     // OUTDIR/pairs/*.json of `boicp map`
  kPairListing = 1u << 1,  // pairs.json of `boicp map`
  kPairApi = 1u << 2,      // boicp.v1.PairResult, and the JSON of `boicp show` and `results`
};

/// Where a field's value lives in PairResult.
using PairResultMember =
    std::variant<Transform PairResult::*, InformationMatrix PairResult::*, double PairResult::*,
                 std::optional<double> PairResult::*, bool PairResult::*, Rung PairResult::*,
                 int PairResult::*, uint64_t PairResult::*, std::string PairResult::*,
                 std::optional<std::vector<FreeSlide>> PairResult::*>;

struct PairResultField {
  const char* name;  // the JSON key, and the boicp.v1.PairResult field
  PairResultMember member;
  unsigned formats;  // PairResultFormat bits
};

/// Every field of PairResult but its key, in the order the formats list them.
const std::vector<PairResultField>& PairResultFields();

}  // namespace boicp
