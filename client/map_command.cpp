// `boicp map`: a scan folder to an OctoMap and a trajectory in one process,
// no daemon, through core's map pipeline as the daemon runs it.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "boicp/util/parallel_for.hpp"
#include "commands.hpp"
#include "local_map.hpp"
#include "map_settings_flags.hpp"
#include "run_command.hpp"

namespace boicp::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct MapFlags {
  MapSettingsFlags map;
  std::string out_dir;
  std::string shard;  // "K/N"; empty = the whole run
  int threads = AvailableCores();
  uint64_t max_fusion_mb = 0;
  bool json = false;
};

struct Shard {
  int index = 0;  // K, 1-based
  int count = 0;  // N
};

Shard ParseShard(const std::string& text) {
  Shard shard;
  char end = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &shard.index, &shard.count, &end) != 2 ||
      shard.count < 1 || shard.index < 1 || shard.index > shard.count) {
    throw InputError("--shard: expected K/N with 1 <= K <= N, got '" + text + "'");
  }
  return shard;
}

// Shards share OUTDIR/run.json: the first writes it, the others must agree.
void CheckShardManifest(const LocalRun& run, const std::string& out) {
  const std::string manifest = RunManifestPath(out);
  if (!fs::exists(manifest)) return;
  const std::string differences = ManifestDifferences(ReadRunManifest(out), run.settings);
  if (!differences.empty()) {
    throw InputError(manifest + " holds another run's settings (" + differences +
                     "); use a fresh OUTDIR");
  }
}

void ClaimShardManifest(const LocalRun& run, const std::string& out) {
  if (!fs::exists(RunManifestPath(out))) WriteRunManifest(run, out);
}

// A shard registers the pairs whose index in the plan is K-1 modulo N and
// writes only their files and the manifest; `boicp merge` builds the map.
int RunShard(const LocalRun& run, const Shard& shard, const MapFlags& flags) {
  const std::string& out = flags.out_dir;
  const std::vector<PairIndex> all = FixedPlanPairs(run.batch.plan);
  std::vector<PairIndex> mine;
  for (size_t i = 0; i < all.size(); ++i) {
    if (static_cast<int>(i % static_cast<size_t>(shard.count)) == shard.index - 1) {
      mine.push_back(all[i]);
    }
  }
  std::fprintf(stderr, "shard %d/%d: %zu of %zu pairs\n", shard.index, shard.count, mine.size(),
               all.size());
  const int reused = RegisterLocalPairs(run, mine, out, flags.threads);
  std::fprintf(stderr, "shard %d/%d done; when every shard is, run: boicp merge %s -o OUTDIR\n",
               shard.index, shard.count, out.c_str());
  if (flags.json) {
    std::cout << json{{"shard", flags.shard},
                      {"pairs", mine.size()},
                      {"pairs_total", all.size()},
                      {"pairs_reused", reused},
                      {"pairs_dir", (fs::path(out) / "pairs").string()}}
                     .dump()
              << std::endl;
  }
  return kOk;
}

// The whole run: every pair (reusing finished ones), then the map.
int BuildMap(const LocalRun& run, const MapFlags& flags,
             std::chrono::steady_clock::time_point start) {
  const std::string& out = flags.out_dir;
  WriteRunManifest(run, out);

  const MapOutputSummary summary = BuildLocalMap(run, out, flags.threads);
  PrintMapClosing(summary, out);
  if (flags.json) {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << MapSummaryJson(run, summary, out, seconds).dump() << std::endl;
  }
  return kOk;
}

int RunMap(MapFlags flags) {
  const auto start = std::chrono::steady_clock::now();
  if (flags.out_dir.empty()) throw InputError("-o OUTDIR is required");
  if (flags.threads < 1) throw InputError("--threads: must be >= 1");
  LocalRun run = PrepareRun(WithAbsolutePaths(ResolveMapSettings(flags.map)));
  const std::string& out = flags.out_dir;
  const bool sharded = !flags.shard.empty();
  const Shard shard = sharded ? ParseShard(flags.shard) : Shard{};
  if (sharded && run.batch.plan.keyframes) {
    throw InputError(
        "--shard: overlap pairing chooses its pairs as results come in; shard "
        "consecutive or explicit pairing");
  }
  if (sharded) CheckShardManifest(run, out);
  // Shards fuse nothing, but their merge would refuse what this refuses.
  ChooseMapRunSettings(run, flags.threads, flags.max_fusion_mb);
  if (run.drive_paths.size() == 1) {
    std::fprintf(stderr, "%s: %s\n", run.settings.path.c_str(), run.description.c_str());
  } else {
    std::fprintf(stderr, "%zu drives, mapped into the first's frame: %s\n", run.drive_paths.size(),
                 run.description.c_str());
  }
  PrintRunSettings(run);
  if (!sharded) return BuildMap(run, flags, start);
  ClaimShardManifest(run, out);
  return RunShard(run, shard, flags);
}

}  // namespace

CommandRunner AddMapCommand(CLI::App& app) {
  auto flags = std::make_shared<MapFlags>();
  MapFlags& f = *flags;
  AddMapSettingsFlags(app, f.map);
  app.add_option("-o,--out", f.out_dir, "Output folder");
  app.add_option("--threads", f.threads,
                 "Pairs registered at once, one thread each (default: every core); the map "
                 "does not depend on it")
      ->capture_default_str();
  app.add_option("--shard", f.shard,
                 "K/N: register only pairs K-1 mod N into OUTDIR/pairs, no map (then merge)");
  AddFusionLimitFlag(app, f.max_fusion_mb);
  app.add_flag("--json", f.json, "Print a JSON summary on stdout");
  return [flags] { return RunCommand("map", [&] { return RunMap(*flags); }); };
}

}  // namespace boicp::cli
