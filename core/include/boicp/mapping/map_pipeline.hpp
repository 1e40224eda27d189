#pragma once
// The map pipeline of a scan batch, one for the daemon and `boicp map`:
// plan -> register pairs (RegisterPlannedPairs) -> poses (EstimatePoses) ->
// fusion and output files (FuseScans). Callers supply where finished pairs
// are stored (PairStore), where progress goes (MapProgressSink) and the
// threads pairs run on (PairExecution); nothing else differs.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/map_batch.hpp"
#include "boicp/mapping/pair_scheduler.hpp"
#include "boicp/mapping/place_recognition.hpp"

namespace boicp {

/// The pose-graph edges of a batch, in the order EstimatePoses wants them:
/// the chain, then the plan's extras that do not pair the same two scans as
/// a chain pair. `pairs[i]` is the pair of `constraints[i]`.
struct GraphEdges {
  std::vector<PairConstraint> constraints;
  std::vector<PairIndex> pairs;
};

/// Preconditions: `registered.finished` holds every pair of
/// registered.chain, plan.extras, registered.bridges and registered.loops.
/// Of the bridges and loops, only the trusted ones (kTrustedFrom) are edges.
GraphEdges GraphConstraints(const PairingPlan& plan, const RegisteredPairs& registered);

/// The bridge stage of a batch whose plan is registered: where a chain pair
/// is doubtful, it is registered the other way round, then the scans
/// around it are registered directly, one scan back (low - 1 onto high),
/// one scan on (low onto high + 1), then both, each round only over chain
/// pairs no trusted bridge spans yet, with the chain's relative pose as the
/// prior and up to the short search. Bridges are stored in `store` and
/// added to registered.finished and registered.bridges; a trusted one is an
/// edge that the chain prefers to the doubtful pair. Throws what
/// RegisterPlannedPairs throws.
void RegisterBridges(const MapBatch& batch, RegisteredPairs& registered, PairStore& store,
                     MapProgressSink& progress, const PairExecution& execution);

/// True when a trusted bridge of `registered` spans the chain pair `link`.
bool IsBridged(const PairIndex& link, const RegisteredPairs& registered);

/// "3 of 5 doubtful chain pairs bridged by a trusted pair over them; 9
/// bridges tried"; empty when no bridge was tried.
std::string BridgeSummaryLine(const RegisteredPairs& registered);

/// What the loop search knows of each scan of a batch, each loaded once:
/// where it looks in the map frame (its points' centroid moved by its pose;
/// its sensor origin when it has no points), its place descriptor on the
/// batch's grid (radius: the median PlaceRadius of up to five scans spread
/// over the batch) and its sensor origin.
struct ScanViews {
  std::vector<Point> centres;
  std::vector<PlaceDescriptor> places;
  std::vector<Point> sensor_origins;
};

/// Precondition: one pose (T_map_scan) per scan. Throws InputError when a
/// scan does not load.
ScanViews ViewScans(const std::vector<ScanSource>& scans, const std::vector<Transform>& poses);

/// The loop stage of a batch whose plan is registered. Candidates found on
/// the poses of `registered` (LoopCandidatesFromPoses, the reach being the
/// batch's translation box; prior: the chain's relative pose), then by
/// place recognition between scans that no trusted pair of `registered`
/// connects (LoopCandidatesFromPlaces, clear of every pair registered or
/// proposed; prior: the match's heading), are registered on `execution` up
/// to the short search, stored in `store` and added to registered.finished
/// and registered.loops. Their progress goes to `progress`; the pairs
/// registered before are not reported again. Throws what
/// RegisterPlannedPairs throws, and InputError when a scan no longer loads.
void RegisterLoopCandidates(const MapBatch& batch, RegisteredPairs& registered, PairStore& store,
                            MapProgressSink& progress, const PairExecution& execution);

/// The stages after the plan's own pairs: RegisterBridges, then
/// RegisterLoopCandidates when batch.map.loops is kAuto.
void RegisterFoundPairs(const MapBatch& batch, RegisteredPairs& registered, PairStore& store,
                        MapProgressSink& progress, const PairExecution& execution);

/// What the loop stage found and what it cost.
struct LoopStageSummary {
  int candidates = 0;          // registered.loops
  int closed = 0;              // of them, in the final graph
  double seconds = 0.0;        // registering the candidates (pair runtimes)
  double other_seconds = 0.0;  // registering every other pair

  /// "3 loops closed of 12 candidates; verifying them took 20 s, 15 % of
  /// the other pairs' 130 s". Empty when there was no candidate.
  std::string Line() const;
};

/// "3 loops closed of 12 candidates".
std::string LoopsClosedText(int closed, int candidates);

LoopStageSummary SummariseLoops(const RegisteredPairs& registered,
                                const std::vector<PairIndex>& in_graph);

/// The edges the final poses use (PoseEstimate::kept), in edge order.
std::vector<PairIndex> PairsInGraph(const GraphEdges& edges, const PoseEstimate& estimate);

struct AssembledMap {
  PoseEstimate estimate;            // poses are T_map_scan
  std::vector<PairIndex> in_graph;  // the pairs the poses use
  /// Why each loop closure, bridge or extra pair the poses do not use was left out.
  std::map<PairIndex, std::string> left_out;
  /// Scans no trusted pair in the graph touches (ScansWithoutTrustedPair).
  std::vector<int> untrusted_scans;
  /// Whether they were left out of the fusion: batch.map.untrusted_scans is
  /// kLeaveOut and some other scan has a trusted pair.
  bool untrusted_left_out = false;
  FusionSummary fusion;
};

/// Work a front end does at fixed points of the pipeline, apart from what
/// it reports. Empty: nothing.
struct MapPipelineHooks {
  /// Once the poses are known and kFusing is reported, before fusion reads
  /// the scans again and writes the outputs (the daemon creates the job's
  /// folder, clears its staging files and re-hashes every scan).
  std::function<void()> before_fusion;
};

/// Poses from the registered pairs, then fusion into `outputs` of every scan
/// but those left out as untrusted (AssembledMap); the trajectories keep
/// every scan. Reports the
/// stages to `progress`, marks the used pairs in `store`, runs `hooks` at
/// their points. Throws InputError when the pairs leave a scan unreached or
/// a scan no longer loads, Cancelled when `stop_requested` fires during
/// fusion, std::runtime_error when an output cannot be written.
AssembledMap AssembleMap(const MapBatch& batch, const RegisteredPairs& registered, PairStore& store,
                         MapProgressSink& progress, const MapOutputPaths& outputs,
                         const std::function<bool()>& stop_requested = {},
                         const MapPipelineHooks& hooks = {});

struct MapPipelineResult {
  RegisteredPairs pairs;
  AssembledMap map;
};

/// The whole pipeline: RegisterPlannedPairs, RegisterFoundPairs, then AssembleMap (with the
/// execution's stop_requested). Throws what any of them throws.
MapPipelineResult RunMapPipeline(const MapBatch& batch, PairStore& store, MapProgressSink& progress,
                                 const PairExecution& execution, const MapOutputPaths& outputs,
                                 const MapPipelineHooks& hooks = {});

}  // namespace boicp
