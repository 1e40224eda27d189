#pragma once
// Local map runs through core's map pipeline: pair results in
// OUTDIR/pairs (PairFileStore), progress on stderr (TerminalProgress),
// pairs on a pool of --threads workers with one registration thread each.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "boicp/mapping/map_pipeline.hpp"
#include "boicp/mapping/map_progress.hpp"
#include "local_pipeline.hpp"

namespace boicp::cli {

struct MapOutputSummary {
  std::vector<Transform> poses;  // T_map_scan
  bool optimised = false;
  size_t occupied_leaves = 0;
  size_t points_out_of_range = 0;  // left out of the map: beyond its key range
  double fusion_s = 0.0;
  int pairs = 0;                  // listed in pairs.json
  int pairs_doubtful = 0;         // of which doubtful
  int pairs_reused = 0;           // taken from OUTDIR/pairs instead of registered
  std::vector<Rung> answered_by;  // of each pair listed, the rung whose answer was kept
  LoopStageSummary loops;         // the loop closures the map looked for itself
  std::string bridges;            // BridgeSummaryLine; empty when none was tried
  int bridges_tried = 0;
  /// File names of the scans with no trusted pair (ScansWithoutTrustedPair).
  std::vector<std::string> untrusted_scans;
  std::string untrusted_line;  // UntrustedScansLine
};

/// What a caller may add to a local run: where progress goes (null: the
/// terminal, as `boicp map`), and a stop request polled between ICP
/// evaluations, pairs and fused scans (true: Cancelled, with every finished
/// pair's file kept for the next run).
struct LocalMapHooks {
  MapProgressSink* progress = nullptr;
  std::function<bool()> stop_requested;
};

/// What `map` and `merge` close with on stderr: the files written into
/// `out_dir`, how many pairs are doubtful and how many each rung answered.
void PrintMapClosing(const MapOutputSummary& summary, const std::string& out_dir);

/// The whole run into OUTDIR: every pair (reusing files with the run's
/// settings), then map.bt, map.ot, trajectory.tum, trajectory.kitti,
/// pairs.json and preview.png. Throws the first failure.
/// Precondition: run.chosen = ChooseBatchSettings(run.batch) was called; threads >= 1.
MapOutputSummary BuildLocalMap(const LocalRun& run, const std::string& out_dir, int threads,
                               const LocalMapHooks& hooks = {});

/// `map --json`'s summary of a run written into `out_dir` in `seconds`:
/// layout, scans, pairs (reused, doubtful), loop candidates, loops closed
/// and the seconds their registration took against the other pairs', whether the pose graph was
/// optimised, occupied leaves, runtime_s and every output file's path.
nlohmann::json MapSummaryJson(const LocalRun& run, const MapOutputSummary& summary,
                              const std::string& out_dir, double seconds);

/// A shard's share: registers `pairs` into OUTDIR/pairs (reusing files with
/// the run's settings), no map. Returns how many were reused.
int RegisterLocalPairs(const LocalRun& run, const std::vector<PairIndex>& pairs,
                       const std::string& out_dir, int threads);

/// `boicp merge`: the map from results already read (ReadStoredPairs, one
/// per pair of run.batch.plan), written to OUTDIR as BuildLocalMap does,
/// with the loop stage's candidates registered on `threads` threads (>= 1).
MapOutputSummary AssembleStoredPairs(const LocalRun& run,
                                     const std::map<PairIndex, PairResult>& results,
                                     const std::string& out_dir, int threads);

}  // namespace boicp::cli
