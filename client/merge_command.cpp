// `boicp merge`: the map of a sharded run. Reads the run.json manifest and
// every per-pair file the shards wrote (one folder or several), refuses
// missing pairs or other settings, and writes the same outputs as `boicp map`.

#include <cstdio>
#include <iostream>

#include "boicp/util/parallel_for.hpp"
#include "commands.hpp"
#include "local_map.hpp"
#include "map_settings_flags.hpp"
#include "run_command.hpp"

namespace boicp::cli {
namespace {

using nlohmann::json;

struct MergeFlags {
  std::vector<std::string> shard_dirs;
  std::string out_dir;
  uint64_t max_fusion_mb = 0;
  bool json = false;
};

// The one manifest all shard folders agree on.
MapSettings AgreedManifest(const std::vector<std::string>& dirs) {
  const MapSettings first = ReadRunManifest(dirs.front());
  for (size_t i = 1; i < dirs.size(); ++i) {
    const std::string differences = ManifestDifferences(first, ReadRunManifest(dirs[i]));
    if (!differences.empty()) {
      throw InputError(RunManifestPath(dirs[i]) + " differs from " + RunManifestPath(dirs.front()) +
                       " (" + differences + ")");
    }
  }
  return first;
}

int RunMerge(const MergeFlags& flags) {
  LocalRun run = PrepareRun(AgreedManifest(flags.shard_dirs));
  if (run.batch.plan.keyframes) {
    throw InputError(RunManifestPath(flags.shard_dirs.front()) +
                     ": overlap pairing is not sharded; run boicp map instead");
  }
  // The shards' own choice: the same scans give the same settings.
  ChooseMapRunSettings(run, AvailableCores(), flags.max_fusion_mb);
  const std::map<PairIndex, PairResult> results =
      ReadStoredPairs(run, FixedPlanPairs(run.batch.plan), flags.shard_dirs);
  std::fprintf(stderr, "%s: %s, %zu pairs\n", run.settings.path.c_str(), run.description.c_str(),
               results.size());
  PrintRunSettings(run);
  WriteRunManifest(run, flags.out_dir);
  const MapOutputSummary summary =
      AssembleStoredPairs(run, results, flags.out_dir, AvailableCores());
  PrintMapClosing(summary, flags.out_dir);
  if (flags.json) {
    std::cout << json{{"scans", run.batch.scans.size()},
                      {"pairs", results.size()},
                      {"pairs_doubtful", summary.pairs_doubtful},
                      {"pose_graph_optimised", summary.optimised},
                      {"occupied_leaves", summary.occupied_leaves},
                      {"out", flags.out_dir}}
                     .dump()
              << std::endl;
  }
  return kOk;
}

}  // namespace

CommandRunner AddMergeCommand(CLI::App& app) {
  auto flags = std::make_shared<MergeFlags>();
  app.add_option("PATH", flags->shard_dirs,
                 "Output folder(s) of the shards (each with run.json and pairs/)")
      ->required();
  app.add_option("-o,--out", flags->out_dir, "Output folder (may be the shards' own)")->required();
  AddFusionLimitFlag(app, flags->max_fusion_mb);
  app.add_flag("--json", flags->json, "Print a JSON summary on stdout");
  return [flags] { return RunCommand("merge", [&] { return RunMerge(*flags); }); };
}

}  // namespace boicp::cli
