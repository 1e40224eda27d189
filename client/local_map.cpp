#include "local_map.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>

#include "boicp/mapping/drives.hpp"
#include "boicp/mapping/map_pipeline.hpp"
#include "boicp/mapping/map_preview.hpp"
#include "boicp/settings/rung_summary.hpp"
#include "boicp/util/atomic_file.hpp"
#include "boicp/util/thread_pool.hpp"
#include "pair_file_store.hpp"
#include "terminal_progress.hpp"

namespace boicp::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

MapOutputPaths LocalOutputPaths(const std::string& out_dir) {
  const fs::path dir(out_dir);
  MapOutputPaths paths;
  paths.octomap_bt = (dir / "map.bt").string();
  paths.octomap_ot = (dir / "map.ot").string();
  paths.trajectory_tum = (dir / "trajectory.tum").string();
  paths.trajectory_kitti = (dir / "trajectory.kitti").string();
  return paths;
}

// Each drive's trajectory files' stem in OUTDIR: "trajectory" for one
// drive; of several, "trajectory-NAME", NAME its folder's or bag's name
// (numbered from 1 when two drives share one).
std::vector<std::string> DriveTrajectoryStems(const LocalRun& run) {
  if (run.drive_paths.size() == 1) return {"trajectory"};
  std::vector<std::string> names;
  for (const std::string& drive : run.drive_paths) {
    fs::path path = fs::path(drive).lexically_normal();
    if (!path.has_filename()) path = path.parent_path();  // "folder/"
    names.push_back(path.stem().string());
  }
  const std::set<std::string> distinct(names.begin(), names.end());
  std::vector<std::string> stems;
  for (size_t d = 0; d < names.size(); ++d) {
    const std::string name =
        distinct.size() == names.size() ? names[d] : std::to_string(d + 1) + "-" + names[d];
    stems.push_back("trajectory-" + name);
  }
  return stems;
}

// The pairs pairs.json lists: a fixed plan's, in plan order, then the
// bridges and the loop candidates; for keyframes every pair, in index order.
std::vector<PairIndex> ListedPairs(const PairingPlan& plan, const RegisteredPairs& registered) {
  std::vector<PairIndex> listed;
  if (!plan.keyframes) {
    listed = plan.chain;
    listed.insert(listed.end(), plan.extras.begin(), plan.extras.end());
    listed.insert(listed.end(), registered.bridges.begin(), registered.bridges.end());
    listed.insert(listed.end(), registered.loops.begin(), registered.loops.end());
    return listed;
  }
  for (const auto& entry : registered.finished) listed.push_back(entry.first);
  return listed;
}

// preview.png and pairs.json of an assembled map.
MapOutputSummary WriteListingAndPreview(const LocalRun& run, const AssembledMap& map,
                                        std::vector<PairResult> listed,
                                        const std::string& out_dir) {
  const fs::path dir(out_dir);
  UpDetectionOptions up_options;
  if (!run.batch.scans.empty())
    up_options.sensor_up = SensorUp(run.batch.config.sensor, run.batch.scans[0].load.format);
  const UpDirection up = WriteMapPreview(LocalOutputPaths(out_dir).octomap_bt, map.estimate.poses,
                                         (dir / "preview.png").string(), {}, up_options);
  std::fprintf(stderr, "preview: %s\n", up.reason.c_str());

  const std::set<PairIndex> in_graph(map.in_graph.begin(), map.in_graph.end());
  json listing = json::array();
  for (PairResult& r : listed) {
    r.in_graph = in_graph.count(r.pair) > 0;
    const auto reason = map.left_out.find(r.pair);
    if (reason != map.left_out.end()) r.left_out_because = reason->second;
    listing.push_back(PairListingJson(run.batch.scans, r));
  }
  WriteTextFileAtomically((dir / "pairs.json").string(), listing.dump(1) + "\n");
  if (run.drive_paths.size() > 1) {
    std::vector<std::string> stems;
    for (const std::string& stem : DriveTrajectoryStems(run))
      stems.push_back((dir / stem).string());
    WriteDriveTrajectories(run.batch.scans, map.estimate.poses, run.batch.pairing.drive_starts,
                           stems);
  }

  MapOutputSummary summary;
  summary.poses = map.estimate.poses;
  summary.optimised = map.estimate.optimised;
  summary.occupied_leaves = map.fusion.occupied_leaves;
  summary.points_out_of_range = map.fusion.points_out_of_range;
  summary.fusion_s = map.fusion.seconds;
  summary.pairs = static_cast<int>(listed.size());
  summary.pairs_doubtful = static_cast<int>(
      std::count_if(listed.begin(), listed.end(), [](const PairResult& r) { return r.doubtful; }));
  for (const PairResult& r : listed) summary.answered_by.push_back(r.answered_by);
  summary.untrusted_scans = ScanFileNames(run.batch.scans, map.untrusted_scans);
  summary.untrusted_line =
      UntrustedScansLine(run.batch.scans, map.untrusted_scans, map.untrusted_left_out);
  return summary;
}

// What the stages after the plan's own pairs did.
void SummariseStages(const RegisteredPairs& registered, const AssembledMap& map,
                     MapOutputSummary& summary) {
  summary.loops = SummariseLoops(registered, map.in_graph);
  summary.bridges = BridgeSummaryLine(registered);
  summary.bridges_tried = static_cast<int>(registered.bridges.size());
}

// Parallelism is across pairs, one registration thread each (config.threads
// is 1), as the daemon's default --registration-threads.
PairExecution LocalExecution(ThreadPool& pool) {
  PairExecution execution;
  execution.submit = [&pool](std::function<void()> task) { pool.Submit(std::move(task)); };
  execution.max_in_flight = pool.size();
  return execution;
}

}  // namespace

void PrintMapClosing(const MapOutputSummary& summary, const std::string& out_dir) {
  std::fprintf(stderr,
               "wrote %s/{map.bt,map.ot,trajectory.tum,trajectory.kitti,pairs.json,"
               "preview.png}: %zu occupied leaves\n",
               out_dir.c_str(), summary.occupied_leaves);
  if (summary.points_out_of_range > 0) {
    std::fprintf(
        stderr,
        "warning: %zu points lie over 32768 leaves from the map origin along an axis, beyond "
        "what an OctoMap can hold, and were left out of the map; a coarser "
        "--resolution reaches farther\n",
        summary.points_out_of_range);
  }
  std::fprintf(stderr, "%s\n", DoubtfulSummary(summary.pairs_doubtful, summary.pairs).c_str());
  const std::string rungs = settings::RungSummary(summary.answered_by);
  if (!rungs.empty()) std::fprintf(stderr, "%s\n", rungs.c_str());
  for (const std::string* line : {&summary.bridges, &summary.untrusted_line}) {
    if (!line->empty()) std::fprintf(stderr, "%s\n", line->c_str());
  }
  const std::string loops = summary.loops.Line();
  if (!loops.empty()) std::fprintf(stderr, "%s\n", loops.c_str());
}

MapOutputSummary BuildLocalMap(const LocalRun& run, const std::string& out_dir, int threads,
                               const LocalMapHooks& hooks) {
  const MapBatch& batch = run.batch;
  PairFileStore store(batch.scans, batch.config, out_dir);
  TerminalProgress terminal;
  MapProgressSink& progress = hooks.progress ? *hooks.progress : terminal;
  fs::create_directories(out_dir);
  MapPipelineResult result;
  {
    ThreadPool pool(threads);
    PairExecution execution = LocalExecution(pool);
    execution.stop_requested = hooks.stop_requested;
    result = RunMapPipeline(batch, store, progress, execution, LocalOutputPaths(out_dir));
  }
  std::vector<PairResult> listed;
  for (const PairIndex& pair : ListedPairs(batch.plan, result.pairs)) {
    listed.push_back(result.pairs.finished.at(pair));
  }
  MapOutputSummary summary = WriteListingAndPreview(run, result.map, listed, out_dir);
  summary.pairs_reused = result.pairs.reused;
  SummariseStages(result.pairs, result.map, summary);
  return summary;
}

nlohmann::json MapSummaryJson(const LocalRun& run, const MapOutputSummary& summary,
                              const std::string& out_dir, double seconds) {
  json outputs;
  for (const char* name :
       {"map.bt", "map.ot", "trajectory.tum", "trajectory.kitti", "pairs.json", "preview.png"}) {
    outputs[name] = (fs::path(out_dir) / name).string();
  }
  // Each drive with its trajectory files' names; several drives' files are
  // outputs too.
  json drives = json::array();
  const std::vector<std::string> stems = DriveTrajectoryStems(run);
  for (size_t d = 0; d < run.drive_paths.size(); ++d) {
    const auto [first, end] =
        DriveScans(run.batch.pairing.drive_starts, static_cast<int>(run.batch.scans.size()), d);
    for (const char* extension : {".tum", ".kitti"}) {
      const std::string name = stems[d] + extension;
      outputs[name] = (fs::path(out_dir) / name).string();
    }
    drives.push_back({{"path", run.drive_paths[d]},
                      {"first_scan", first},
                      {"scans", end - first},
                      {"trajectory_tum", stems[d] + ".tum"},
                      {"trajectory_kitti", stems[d] + ".kitti"}});
  }
  return {{"layout", ScanLayoutName(run.layout)},
          {"scans", run.batch.scans.size()},
          {"pairs", summary.pairs},
          {"pairs_reused", summary.pairs_reused},
          {"pairs_doubtful", summary.pairs_doubtful},
          {"bridges_tried", summary.bridges_tried},
          {"untrusted_scans", summary.untrusted_scans},
          {"loop_candidates", summary.loops.candidates},
          {"loops_closed", summary.loops.closed},
          {"loop_runtime_s", summary.loops.seconds},
          {"other_pairs_runtime_s", summary.loops.other_seconds},
          {"pose_graph_optimised", summary.optimised},
          {"occupied_leaves", summary.occupied_leaves},
          {"runtime_s", seconds},
          {"outputs", outputs},
          {"drives", drives}};
}

int RegisterLocalPairs(const LocalRun& run, const std::vector<PairIndex>& pairs,
                       const std::string& out_dir, int threads) {
  const MapBatch& batch = run.batch;
  PairFileStore store(batch.scans, batch.config, out_dir);
  TerminalProgress progress;
  ThreadPool pool(threads);
  const RegisteredPairs registered =
      RegisterPlannedPairs(batch.scans, batch.config, batch.scale, PlanFixedPairs(pairs), store,
                           progress, LocalExecution(pool));
  progress.FinishPairs();
  return registered.reused;
}

MapOutputSummary AssembleStoredPairs(const LocalRun& run,
                                     const std::map<PairIndex, PairResult>& results,
                                     const std::string& out_dir, int threads) {
  const MapBatch& batch = run.batch;
  RegisteredPairs registered;
  registered.finished = results;
  registered.chain = batch.plan.chain;
  PairFileStore store(batch.scans, batch.config, out_dir);
  TerminalProgress progress;
  fs::create_directories(out_dir);
  {
    ThreadPool pool(threads);
    RegisterFoundPairs(batch, registered, store, progress, LocalExecution(pool));
  }
  const AssembledMap map =
      AssembleMap(batch, registered, store, progress, LocalOutputPaths(out_dir));
  std::vector<PairResult> listed;
  for (const PairIndex& pair : ListedPairs(batch.plan, registered))
    listed.push_back(registered.finished.at(pair));
  MapOutputSummary summary = WriteListingAndPreview(run, map, listed, out_dir);
  SummariseStages(registered, map, summary);
  return summary;
}

}  // namespace boicp::cli
