// `boicp show JOB`: a job's summary and its per-pair results.

#include <cstdio>
#include <iostream>
#include <optional>
#include <vector>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/settings/rung_summary.hpp"
#include "commands.hpp"
#include "duration_text.hpp"
#include "printable_text.hpp"
#include "remote_json.hpp"
#include "remote_options.hpp"
#include "remote_watch.hpp"

namespace boicp::cli {
namespace {

struct ShowFlags {
  RemoteFlags remote;
  std::string job_id;
  bool json = false;
};

// One line of the pair table; T_target_source summarised by its translation
// and rotation angle.
void PrintPair(const v1::PairResult& p) {
  const Transform T = rpc::TransformFromProto(p.transform(), "pair.transform");
  char overlap[32] = "-";  // unknown in results stored before it was computed
  if (p.has_overlap()) std::snprintf(overlap, sizeof overlap, "%.3f", p.overlap());
  std::printf("%6u %6u %8.3f %8s %10.3f %11.4f %8.4f %12s %7u %9.3f %9.2f %5s%s%s\n", p.source(),
              p.target(), p.fitness(), overlap, p.confidence(), p.inlier_rmse(), p.objective(),
              rpc::AnsweredBy(p).c_str(), p.evaluations(), TranslationNorm(T),
              RotationAngle(T) * 180.0 / M_PI, FormatDuration(p.runtime_s()).c_str(),
              p.doubtful() ? "  doubtful" : "", p.in_graph() ? "" : "  (not in graph)");
}

// The pair table, closed by the count of doubtful pairs and of the rung
// that answered them.
void PrintPairs(const v1::JobResults& results) {
  std::printf("\n%6s %6s %8s %8s %10s %11s %8s %12s %7s %9s %9s %5s\n", "source", "target",
              "fitness", "overlap", "confidence", "rmse_m", "objective", "answered_by", "evals",
              "transl_m", "rot_deg", "time");
  int doubtful = 0;
  std::vector<Rung> answered_by;
  for (const v1::PairResult& p : results.pairs()) {
    PrintPair(p);
    if (p.doubtful()) ++doubtful;
    // A rung of a newer daemon that this client does not know goes uncounted.
    if (const std::optional<Rung> rung = settings::RungFromName(rpc::AnsweredBy(p))) {
      answered_by.push_back(*rung);
    }
  }
  std::printf("\n%s\n", DoubtfulSummary(doubtful, results.pairs_size()).c_str());
  std::printf("%s\n", settings::RungSummary(answered_by).c_str());
}

void PrintSummary(const v1::JobResults& results) {
  const v1::Job& job = results.job();
  std::printf("job         %s\n", job.job_id().c_str());
  if (!job.label().empty()) std::printf("label       %s\n", PrintableText(job.label()).c_str());
  std::printf("state       %s (stage %s)%s\n", rpc::JobStateName(job.state()).c_str(),
              PrintableText(job.stage()).c_str(),
              job.cancel_requested() ? ", cancel requested" : "");
  std::printf("scans       %u\n", job.num_scans());
  std::printf("pairs       %u of %u done, %u doubtful%s\n", job.pairs_done(), job.pairs_total(),
              job.pairs_doubtful(), job.pose_graph_optimised() ? ", pose graph optimised" : "");
  if (job.started_at() > 0.0) {
    const double end = job.finished_at() > 0.0 ? job.finished_at() : job.started_at();
    std::printf("run time    %s%s\n", FormatDuration(end - job.started_at()).c_str(),
                job.finished_at() > 0.0 ? "" : " so far");
  }
  if (!job.error().empty()) std::printf("error       %s\n", PrintableText(job.error()).c_str());
  if (job.has_settings())
    std::printf("settings    %s\n", DescribeChosenSettings(job.settings()).c_str());
  std::vector<std::string> scan_ids(static_cast<size_t>(job.num_scans()));
  for (const v1::TrajectoryPose& pose : results.trajectory()) {
    if (pose.index() < scan_ids.size()) scan_ids[pose.index()] = pose.scan_id();
  }
  for (const std::string& line : MapOutcomeLines(job, scan_ids)) {
    std::printf("map         %s\n", PrintableText(line).c_str());
  }
  if (results.pairs_size() > 0) PrintPairs(results);
}

}  // namespace

CommandRunner AddShowCommand(CLI::App& app) {
  auto flags = std::make_shared<ShowFlags>();
  app.add_option("JOB", flags->job_id, "Job id")->required();
  app.add_flag("--json", flags->json,
               "Print one JSON object: the job's fields, \"pairs\" (T_target_source as 4x4 "
               "row-major) and \"trajectory\" (T_map_scan)");
  AddRemoteOptions(app, flags->remote);
  return [flags] {
    return RunRemote("show", flags->remote, [&] {
      Daemon daemon = ConnectToDaemon(flags->remote);
      const v1::JobResults results = daemon.client->Results(flags->job_id);
      if (flags->json) {
        std::cout << ResultsToJson(results).dump() << std::endl;
      } else {
        PrintSummary(results);
      }
      return kOk;
    });
  };
}

}  // namespace boicp::cli
