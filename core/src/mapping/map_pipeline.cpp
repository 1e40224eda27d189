#include "boicp/mapping/map_pipeline.hpp"

#include <algorithm>
#include <set>
#include <utility>

#include "boicp/mapping/batch_pair.hpp"

namespace boicp {
namespace {

std::pair<int, int> Unordered(const PairIndex& p) {
  return {std::min(p.source, p.target), std::max(p.source, p.target)};
}

}  // namespace

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
  return edges;
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
      EstimatePoses(batch.scans, edges.constraints, BatchPoseGraphOptions(batch.config));
  assembled.in_graph = PairsInGraph(edges, assembled.estimate);
  store.MarkInGraph(assembled.in_graph);
  progress.PosesEstimated(assembled.estimate, assembled.in_graph);

  progress.StageStarted(MapStage::kFusing, static_cast<int>(batch.scans.size()));
  if (hooks.before_fusion) hooks.before_fusion();
  AssemblyCallbacks callbacks;
  callbacks.stop_requested = stop_requested;
  callbacks.progress = [&progress](const AssemblyProgress& p) { progress.AssemblyStep(p); };
  assembled.fusion =
      FuseScans(batch.scans, assembled.estimate.poses, batch.map, outputs, callbacks);
  return assembled;
}

MapPipelineResult RunMapPipeline(const MapBatch& batch, PairStore& store, MapProgressSink& progress,
                                 const PairExecution& execution, const MapOutputPaths& outputs,
                                 const MapPipelineHooks& hooks) {
  MapPipelineResult result;
  result.pairs = RegisterPlannedPairs(batch.scans, batch.config, batch.scale, batch.plan, store,
                                      progress, execution);
  result.map =
      AssembleMap(batch, result.pairs, store, progress, outputs, execution.stop_requested, hooks);
  return result;
}

}  // namespace boicp
