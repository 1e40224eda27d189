#include "boicp/mapping/map_pipeline.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <set>
#include <utility>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/drives.hpp"
#include "boicp/mapping/loop_candidates.hpp"

namespace boicp {
namespace {

std::pair<int, int> Unordered(const PairIndex& p) {
  return {std::min(p.source, p.target), std::max(p.source, p.target)};
}

// Where a bridge over a doubtful chain pair between scans low < high starts
// and ends: `back` scans before low, `on` scans after high; or, `reversed`,
// the chain pair itself the other way round.
struct BridgeOffset {
  int back = 0;
  int on = 0;
  bool reversed = false;
};

// Tried in this order, each only over chain pairs no trusted bridge spans
// yet: the pair reversed (the registration measures how much of the source
// the target explains, and a sparse ring LiDAR's scan a few metres on may
// explain less of the other than the other explains of it), one scan back,
// one scan on, then both.
constexpr BridgeOffset kBridgeOffsets[] = {
    {0, 0, true}, {1, 0, false}, {0, 1, false}, {1, 1, false}};

// The bridge `offset` puts over the chain pair `link`, if not registered yet
// and within the link's drive.
std::optional<PairIndex> BridgeOver(const PairIndex& link, const BridgeOffset& offset,
                                    int num_scans, const std::vector<int>& drive_starts,
                                    const RegisteredPairs& registered,
                                    std::set<std::pair<int, int>>& registered_already) {
  if (offset.reversed) {
    const PairIndex reversed{link.target, link.source};
    if (registered.finished.count(reversed) != 0) return std::nullopt;
    return reversed;
  }
  const auto [low, high] = Unordered(link);
  const PairIndex bridge{low - offset.back, high + offset.on};
  if (bridge.source < 0 || bridge.target >= num_scans ||
      DriveOf(drive_starts, bridge.source) != DriveOf(drive_starts, low) ||
      DriveOf(drive_starts, bridge.target) != DriveOf(drive_starts, high) ||
      !registered_already.insert(Unordered(bridge)).second) {
    return std::nullopt;
  }
  return bridge;
}

// The grid every scan of the batch is described on: its radius the median
// PlaceRadius of up to five scans spread over the batch.
PlaceGrid BatchPlaceGrid(const std::vector<ScanSource>& scans) {
  constexpr size_t kSampled = 5;
  const size_t count = std::min(kSampled, scans.size());
  std::vector<double> radii;
  for (size_t k = 0; k < count; ++k) {
    const ScanSource& scan = scans[count == 1 ? 0 : k * (scans.size() - 1) / (count - 1)];
    radii.push_back(PlaceRadius(LoadPointCloud(scan.path, scan.load).points, scan.sensor_origin));
  }
  std::nth_element(radii.begin(), radii.begin() + static_cast<std::ptrdiff_t>(count / 2),
                   radii.end());
  PlaceGrid grid;
  grid.max_radius = radii[count / 2];
  return grid;
}

// A later stage's progress: only the pairs it registers are new, and they
// are counted on from the pairs the stages before it finished. Its plan
// holds those again, so of the pairs it loads from the store only the ones
// they do not hold were reused by this stage.
class StageProgress : public MapProgressSink {
 public:
  StageProgress(MapProgressSink& inner, const RegisteredPairs& before)
      : inner_(inner), before_(static_cast<int>(before.finished.size())) {
    for (const auto& entry : before.finished) finished_before_.insert(entry.first);
  }
  void PairFinished(const PairResult& pair, bool reused, const PairCounts& counts) override {
    if (reused) {
      ++reused_;
      if (finished_before_.count(pair.pair) == 0) ++reused_new_;
      return;
    }
    PairCounts continued = counts;
    continued.done = before_ + counts.done - reused_;
    continued.total = before_ + counts.total - reused_;
    inner_.PairFinished(pair, reused, continued);
  }
  void PairFailed(const PairIndex& pair, const std::string& message) override {
    inner_.PairFailed(pair, message);
  }
  void Heartbeat() override { inner_.Heartbeat(); }
  int ReusedNew() const { return reused_new_; }

 private:
  MapProgressSink& inner_;
  int before_ = 0;
  std::set<PairIndex> finished_before_;
  int reused_ = 0;
  int reused_new_ = 0;
};

bool IsTrusted(const PairResult& result) { return result.confidence >= kTrustedFrom; }

// Each scan's piece: scans that trusted pairs connect, however indirectly,
// share one label (the smallest index among them).
std::vector<int> TrustedPieces(int num_scans, const RegisteredPairs& registered) {
  std::vector<PairIndex> trusted;
  for (const auto& [pair, result] : registered.finished) {
    if (IsTrusted(result)) trusted.push_back(pair);
  }
  return ConnectedParts(num_scans, trusted);
}

// Why each edge the poses do not use, and each bridge or loop candidate
// that was no edge, was left out.
std::map<PairIndex, std::string> LeftOut(const GraphEdges& edges, const RegisteredPairs& registered,
                                         const PoseEstimate& estimate) {
  std::map<PairIndex, std::string> left_out;
  for (const auto* found : {&registered.bridges, &registered.loops}) {
    for (const PairIndex& p : *found) {
      const PairResult& result = registered.finished.at(p);
      if (IsTrusted(result)) continue;
      char reason[96];
      std::snprintf(reason, sizeof(reason), "not trusted as a %s (confidence %.3f < %.2f)",
                    result.kind.c_str(), result.confidence, kTrustedFrom);
      left_out[p] = reason;
    }
  }
  for (size_t i = 0; i < edges.pairs.size(); ++i) {
    if (!estimate.kept.at(i)) left_out[edges.pairs[i]] = estimate.left_out_because.at(i);
  }
  return left_out;
}

// Throws InputError naming each drive that the pairs in the graph join to
// no other: several drives make one map only where they overlap.
void RequireDrivesJoined(const MapBatch& batch, const std::vector<PairIndex>& in_graph) {
  const std::vector<int>& starts = batch.pairing.drive_starts;
  const std::vector<int> apart =
      DrivesApartFromTheFirst(static_cast<int>(batch.scans.size()), starts, in_graph);
  if (apart.empty()) return;
  std::string named;
  for (const int drive : apart) {
    const int first = starts[static_cast<size_t>(drive - 1)];
    named += (named.empty() ? "" : "; ") + std::string("drive ") + std::to_string(drive + 1) +
             " (from " + batch.scans[static_cast<size_t>(first)].path + ")";
  }
  throw InputError(named + (apart.size() == 1 ? ": overlaps" : ": overlap") +
                   " no other drive; no trusted pair joins " + (apart.size() == 1 ? "it" : "them") +
                   " to the first drive's map (its pairs are kept for a rerun)");
}

}  // namespace

ScanViews ViewScans(const std::vector<ScanSource>& scans, const std::vector<Transform>& poses) {
  const PlaceGrid grid = BatchPlaceGrid(scans);
  ScanViews views;
  for (size_t i = 0; i < scans.size(); ++i) {
    const Points points = LoadPointCloud(scans[i].path, scans[i].load).points;
    Point centroid = scans[i].sensor_origin;
    if (!points.empty()) {
      centroid = Point::Zero();
      for (const Point& p : points) centroid += p;
      centroid /= static_cast<double>(points.size());
    }
    views.centres.push_back(poses[i].topLeftCorner<3, 3>() * centroid +
                            poses[i].topRightCorner<3, 1>());
    views.places.push_back(grid.max_radius > 0.0
                               ? DescribePlace(points, scans[i].sensor_origin, grid)
                               : PlaceDescriptor{});
    views.sensor_origins.push_back(scans[i].sensor_origin);
  }
  return views;
}

GraphEdges GraphConstraints(const PairingPlan& plan, const RegisteredPairs& registered) {
  GraphEdges edges;
  std::set<std::pair<int, int>> in_chain;
  const auto add = [&](const PairIndex& p) {
    edges.constraints.push_back(ConstraintOf(registered.finished.at(p)));
    edges.pairs.push_back(p);
  };
  for (const PairIndex& p : registered.chain) {
    in_chain.insert(Unordered(p));
    add(p);
  }
  // Loop closures; a keyframe chain may already hold the same two scans.
  for (const PairIndex& p : plan.extras) {
    if (in_chain.count(Unordered(p)) == 0) add(p);
  }
  for (const auto* found : {&registered.bridges, &registered.loops}) {
    for (const PairIndex& p : *found) {
      if (IsTrusted(registered.finished.at(p))) add(p);
    }
  }
  return edges;
}

void RegisterBridges(const MapBatch& batch, RegisteredPairs& registered, PairStore& store,
                     MapProgressSink& progress, const PairExecution& execution) {
  const int num_scans = static_cast<int>(batch.scans.size());
  std::set<std::pair<int, int>> registered_already;
  for (const auto& entry : registered.finished) registered_already.insert(Unordered(entry.first));
  for (const BridgeOffset& offset : kBridgeOffsets) {
    std::vector<PairIndex> open;
    for (const PairIndex& link : registered.chain) {
      if (!IsTrusted(registered.finished.at(link)) && !IsBridged(link, registered)) {
        open.push_back(link);
      }
    }
    if (open.empty()) return;
    const PoseEstimate chained =
        EstimatePoses(batch.scans, GraphConstraints(batch.plan, registered).constraints,
                      BatchPoseGraphOptions(batch.config), batch.pairing.drive_starts);
    PairingPlan plan = PlanFixedPairs(registered.chain, batch.plan.extras);
    std::vector<PairIndex> bridges;
    for (const PairIndex& link : open) {
      const std::optional<PairIndex> over = BridgeOver(
          link, offset, num_scans, batch.pairing.drive_starts, registered, registered_already);
      if (!over) continue;
      const PairIndex bridge = *over;
      plan.extras.push_back(bridge);
      plan.found_priors[bridge] = chained.poses[static_cast<size_t>(bridge.target)].inverse() *
                                  chained.poses[static_cast<size_t>(bridge.source)];
      plan.bridges.insert(bridge);
      bridges.push_back(bridge);
    }
    if (bridges.empty()) continue;
    StageProgress bridge_progress(progress, registered);
    RegisteredPairs found = RegisterPlannedPairs(batch.scans, batch.config, batch.scale, plan,
                                                 store, bridge_progress, execution);
    registered.reused += bridge_progress.ReusedNew();
    for (const PairIndex& p : bridges) {
      registered.finished[p] = std::move(found.finished.at(p));
      registered.bridges.push_back(p);
    }
  }
}

bool IsBridged(const PairIndex& link, const RegisteredPairs& registered) {
  const auto [low, high] = Unordered(link);
  for (const PairIndex& bridge : registered.bridges) {
    const auto [from, to] = Unordered(bridge);
    if (from <= low && to >= high && IsTrusted(registered.finished.at(bridge))) return true;
  }
  return false;
}

std::string BridgeSummaryLine(const RegisteredPairs& registered) {
  if (registered.bridges.empty()) return "";
  int doubtful = 0, bridged = 0;
  for (const PairIndex& link : registered.chain) {
    if (IsTrusted(registered.finished.at(link))) continue;
    ++doubtful;
    bridged += IsBridged(link, registered);
  }
  const size_t tried = registered.bridges.size();
  return std::to_string(bridged) + " of " + std::to_string(doubtful) +
         " doubtful chain pairs bridged by a trusted pair over them; " + std::to_string(tried) +
         (tried == 1 ? " bridge" : " bridges") + " tried";
}

void RegisterLoopCandidates(const MapBatch& batch, RegisteredPairs& registered, PairStore& store,
                            MapProgressSink& progress, const PairExecution& execution) {
  const PoseEstimate chained =
      EstimatePoses(batch.scans, GraphConstraints(batch.plan, registered).constraints,
                    BatchPoseGraphOptions(batch.config), batch.pairing.drive_starts);
  LoopCandidateOptions options;
  options.reach = batch.config.translation_bounds.maxCoeff();
  std::set<std::pair<int, int>> registered_already;
  for (const auto& entry : registered.finished) registered_already.insert(Unordered(entry.first));

  PairingPlan plan = PlanFixedPairs(registered.chain, batch.plan.extras);
  std::vector<PairIndex> loops;
  const auto propose = [&](const LoopCandidate& c) {
    if (registered_already.count(Unordered(c.pair)) != 0) return;
    plan.extras.push_back(c.pair);
    plan.found_priors[c.pair] = c.prior;
    if (c.found_by == LoopFoundBy::kPlace) plan.places.insert(c.pair);
    loops.push_back(c.pair);
  };
  const ScanViews views = ViewScans(batch.scans, chained.poses);
  // Drives not joined yet have poses in frames of their own.
  const std::vector<int>& drive_starts = batch.pairing.drive_starts;
  for (const LoopCandidate& c : LoopCandidatesFromPoses(chained.poses, views.centres, options)) {
    if (DriveOf(drive_starts, c.pair.source) == DriveOf(drive_starts, c.pair.target)) propose(c);
  }
  // Place recognition joins only scans no trusted pair connects yet; pairs
  // already registered or proposed are not proposed again, nor their
  // neighbours: one closure per revisit stretch.
  std::vector<PairIndex> taken = loops;
  for (const auto& entry : registered.finished) {
    const auto [earlier, later] = Unordered(entry.first);
    taken.push_back({later, earlier});
  }
  const std::vector<int> pieces = TrustedPieces(static_cast<int>(batch.scans.size()), registered);
  for (const LoopCandidate& c : LoopCandidatesFromPlaces(views.places, views.sensor_origins, pieces,
                                                         taken, options, drive_starts)) {
    propose(c);
  }
  if (loops.empty()) return;
  StageProgress loop_progress(progress, registered);
  RegisteredPairs found = RegisterPlannedPairs(batch.scans, batch.config, batch.scale, plan, store,
                                               loop_progress, execution);
  registered.reused += loop_progress.ReusedNew();
  for (const PairIndex& p : loops) registered.finished[p] = std::move(found.finished.at(p));
  registered.loops = std::move(loops);
}

void RegisterFoundPairs(const MapBatch& batch, RegisteredPairs& registered, PairStore& store,
                        MapProgressSink& progress, const PairExecution& execution) {
  RegisterBridges(batch, registered, store, progress, execution);
  if (batch.map.loops == LoopSearch::kAuto) {
    RegisterLoopCandidates(batch, registered, store, progress, execution);
  }
}

LoopStageSummary SummariseLoops(const RegisteredPairs& registered,
                                const std::vector<PairIndex>& in_graph) {
  const std::set<PairIndex> used(in_graph.begin(), in_graph.end());
  const std::set<PairIndex> loops(registered.loops.begin(), registered.loops.end());
  LoopStageSummary summary;
  summary.candidates = static_cast<int>(loops.size());
  for (const auto& [pair, result] : registered.finished) {
    if (loops.count(pair) == 0) {
      summary.other_seconds += result.runtime_s;
      continue;
    }
    summary.seconds += result.runtime_s;
    summary.closed += used.count(pair) != 0;
  }
  return summary;
}

std::string LoopsClosedText(int closed, int candidates) {
  return std::to_string(closed) + (closed == 1 ? " loop" : " loops") + " closed of " +
         std::to_string(candidates) + (candidates == 1 ? " candidate" : " candidates");
}

std::string LoopStageSummary::Line() const {
  if (candidates == 0) return "";
  char cost[120];
  std::snprintf(cost, sizeof(cost),
                "; verifying them took %.0f s, %.0f %% of the other pairs' %.0f s", seconds,
                other_seconds > 0.0 ? 100.0 * seconds / other_seconds : 0.0, other_seconds);
  return LoopsClosedText(closed, candidates) + cost;
}

std::vector<PairIndex> PairsInGraph(const GraphEdges& edges, const PoseEstimate& estimate) {
  std::vector<PairIndex> kept;
  for (size_t i = 0; i < edges.pairs.size(); ++i) {
    if (estimate.kept.at(i)) kept.push_back(edges.pairs[i]);
  }
  return kept;
}

AssembledMap AssembleMap(const MapBatch& batch, const RegisteredPairs& registered, PairStore& store,
                         MapProgressSink& progress, const MapOutputPaths& outputs,
                         const std::function<bool()>& stop_requested,
                         const MapPipelineHooks& hooks) {
  const GraphEdges edges = GraphConstraints(batch.plan, registered);
  const bool loops = edges.constraints.size() + 1 > batch.scans.size();
  progress.StageStarted(loops ? MapStage::kOptimising : MapStage::kChaining, 1);
  AssembledMap assembled;
  assembled.estimate =
      EstimatePoses(batch.scans, edges.constraints, BatchPoseGraphOptions(batch.config),
                    batch.pairing.drive_starts);
  assembled.in_graph = PairsInGraph(edges, assembled.estimate);
  RequireDrivesJoined(batch, assembled.in_graph);
  assembled.left_out = LeftOut(edges, registered, assembled.estimate);
  store.MarkInGraph(assembled.in_graph, assembled.left_out);
  progress.PosesEstimated(assembled.estimate, assembled.in_graph);

  const int num_scans = static_cast<int>(batch.scans.size());
  assembled.untrusted_scans =
      ScansWithoutTrustedPair(num_scans, edges.constraints, assembled.estimate.kept);
  // With no trusted pair at all, there is nothing better to fuse instead.
  assembled.untrusted_left_out = batch.map.untrusted_scans == UntrustedScans::kLeaveOut &&
                                 !assembled.untrusted_scans.empty() &&
                                 static_cast<int>(assembled.untrusted_scans.size()) < num_scans;
  std::vector<ScanSource> fused_scans;
  std::vector<Transform> fused_poses;
  const std::set<int> left_out(assembled.untrusted_scans.begin(), assembled.untrusted_scans.end());
  for (int i = 0; i < num_scans; ++i) {
    if (assembled.untrusted_left_out && left_out.count(i) != 0) continue;
    fused_scans.push_back(batch.scans[static_cast<size_t>(i)]);
    fused_poses.push_back(assembled.estimate.poses[static_cast<size_t>(i)]);
  }
  // The trajectories keep every scan, fused or not.
  MapOutputPaths fusion_outputs = outputs;
  fusion_outputs.trajectory_tum.clear();
  fusion_outputs.trajectory_kitti.clear();

  progress.StageStarted(MapStage::kFusing, static_cast<int>(fused_scans.size()));
  if (hooks.before_fusion) hooks.before_fusion();
  AssemblyCallbacks callbacks;
  callbacks.stop_requested = stop_requested;
  callbacks.progress = [&progress](const AssemblyProgress& p) { progress.AssemblyStep(p); };
  assembled.fusion = FuseScans(fused_scans, fused_poses, batch.map, fusion_outputs, callbacks);
  WriteTrajectories(batch.scans, assembled.estimate.poses, outputs);
  return assembled;
}

MapPipelineResult RunMapPipeline(const MapBatch& batch, PairStore& store, MapProgressSink& progress,
                                 const PairExecution& execution, const MapOutputPaths& outputs,
                                 const MapPipelineHooks& hooks) {
  MapPipelineResult result;
  result.pairs = RegisterPlannedPairs(batch.scans, batch.config, batch.scale, batch.plan, store,
                                      progress, execution);
  RegisterFoundPairs(batch, result.pairs, store, progress, execution);
  result.map =
      AssembleMap(batch, result.pairs, store, progress, outputs, execution.stop_requested, hooks);
  return result;
}

}  // namespace boicp
