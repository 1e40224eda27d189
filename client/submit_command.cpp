// `boicp submit PATH`: reads a folder of scans or a bag, checks that every scan
// loads, uploads what the daemon lacks, submits one batch and prints its
// job id alone on stdout (with --wait, then follows it like watch).

#include <chrono>
#include <cstdio>

#include "boicp/rpc/proto_convert.hpp"
#include "boicp/util/parallel_for.hpp"
#include "cli_parsing.hpp"
#include "commands.hpp"
#include "local_pipeline.hpp"
#include "map_settings_flags.hpp"
#include "remote_options.hpp"
#include "remote_watch.hpp"
#include "submit_request.hpp"

namespace boicp::cli {
namespace {

using Clock = std::chrono::steady_clock;

struct SubmitFlags {
  RemoteFlags remote;
  MapSettingsFlags map;  // the same settings, flags and validation as `boicp map`
  std::string label;
  bool wait = false;
};

// Uploads every scan (only metadata for bytes the daemon already holds),
// with progress on stderr; returns the scan ids in order.
std::vector<std::string> UploadScans(rpc::MapBuilderClient& client,
                                     const std::vector<ScanSource>& scans,
                                     const std::vector<v1::ScanMetadata>& metadata) {
  const bool terminal = StderrIsTerminal();
  const auto start = Clock::now();
  auto last_line = start;
  std::vector<std::string> ids;
  uint64_t sent_bytes = 0;
  int already = 0;
  const size_t n = scans.size();
  for (size_t i = 0; i < n; ++i) {
    const v1::UploadScanResponse response = client.UploadScan(scans[i], metadata[i]);
    ids.push_back(response.scan_id());
    if (response.already_present()) {
      ++already;
    } else {
      sent_bytes += response.size_bytes();
    }
    const bool due = Clock::now() - last_line > std::chrono::seconds(5);
    if (terminal || due) {
      std::fprintf(stderr,
                   terminal ? "\ruploading %zu/%zu: %.1f MB sent, %d already held\033[K"
                            : "uploading %zu/%zu: %.1f MB sent, %d already held\n",
                   i + 1, n, sent_bytes / 1e6, already);
      last_line = Clock::now();
    }
  }
  if (terminal) std::fputc('\n', stderr);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::fprintf(stderr, "uploaded %zu scans in %.1f s (%.1f MB sent, %d already on the daemon)\n", n,
               seconds, sent_bytes / 1e6, already);
  return ids;
}

int RunSubmit(SubmitFlags& f) {
  const LocalRun run = PrepareRun(ResolveMapSettings(f.map));
  const std::vector<ScanSource>& scans = run.batch.scans;
  v1::SubmitBatchRequest request = BuildSubmitRequest(run, f.label);
  std::vector<v1::ScanMetadata> metadata;
  for (const ScanSource& scan : scans) metadata.push_back(rpc::ScanMetadataOf(scan));

  Daemon daemon = ConnectToDaemon(f.remote);
  daemon.client->ListJobs(1);  // reachable and the token accepted, before the slow checks
  const auto check_start = Clock::now();
  CheckScansLoad(scans, AvailableCores());
  std::fprintf(stderr, "%s: %s; every scan loads (checked in %.1f s)\n", run.settings.path.c_str(),
               run.description.c_str(),
               std::chrono::duration<double>(Clock::now() - check_start).count());

  for (const std::string& id : UploadScans(*daemon.client, scans, metadata)) {
    request.add_scan_ids(id);
  }
  const v1::Job job = daemon.client->Submit(request);
  std::printf("%s\n", job.job_id().c_str());
  std::fflush(stdout);
  std::fprintf(stderr, "submitted job %s: %u scans, %u pairs planned, preset %s, seed %llu\n",
               job.job_id().c_str(), job.num_scans(), job.pairs_total(),
               request.config().preset().c_str(),
               static_cast<unsigned long long>(request.config().seed()));
  return f.wait ? FollowJob(daemon, job.job_id()) : kOk;
}

}  // namespace

CommandRunner AddSubmitCommand(CLI::App& app) {
  auto flags = std::make_shared<SubmitFlags>();
  SubmitFlags& f = *flags;
  AddMapSettingsFlags(app, f.map, settings::kSubmit);
  app.add_option("--label", f.label, "Free text shown by jobs; default: PATH");
  app.add_flag("--wait", f.wait,
               "Then follow the job like watch; the exit code is watch's (0 only if it "
               "succeeded)");
  AddRemoteOptions(app, f.remote);
  app.footer(
      "Every scan is loaded once before anything is uploaded. Scans the daemon already holds "
      "cost one metadata message. Only the job id goes to stdout.");
  return [flags] { return RunRemote("submit", flags->remote, [&] { return RunSubmit(*flags); }); };
}

}  // namespace boicp::cli
