#include "load_report.hpp"

#include <iomanip>
#include <sstream>

#include "server_fixture.hpp"

namespace boicp::load {
namespace {

constexpr size_t kErrorsShown = 10;

void ListSome(std::vector<std::string>& problems, const std::string& what,
              const std::vector<std::string>& items) {
  for (size_t i = 0; i < items.size() && i < kErrorsShown; ++i) {
    problems.push_back(what + " " + items[i]);
  }
  if (items.size() > kErrorsShown) {
    problems.push_back(what + " ... and " + std::to_string(items.size() - kErrorsShown) + " more");
  }
}

}  // namespace

std::vector<std::string> CheckFigures(const LoadFigures& f, const LoadOptions& options) {
  std::vector<std::string> problems = f.harness_errors;
  for (const ClientTotals* phase : {&f.warmup, &f.main}) {
    const char* name = phase == &f.warmup ? "warm-up" : "main";
    if (phase->jobs_failed > 0) {
      problems.push_back(std::string(name) + ": " + std::to_string(phase->jobs_failed) +
                         " jobs failed");
    }
    if (phase->jobs_unfinished > 0) {
      problems.push_back(std::string(name) + ": " + std::to_string(phase->jobs_unfinished) +
                         " jobs unfinished");
    }
    ListSome(problems, std::string(name) + " job", phase->job_failures);
    ListSome(problems, std::string(name) + " rpc error", phase->rpc.Errors());
  }
  if (f.main.jobs_succeeded == 0) problems.push_back("main: no job completed");
  const double growth = f.after.rss_mb - f.warmed.rss_mb;
  if (growth > options.max_rss_growth_mb) {
    std::ostringstream text;
    text << "RSS grew by " << growth << " MB after the warm-up (bound " << options.max_rss_growth_mb
         << " MB)";
    problems.push_back(text.str());
  }
  if (f.daemon_exit != 0) {
    problems.push_back("boicpd exit code after SIGTERM: " + std::to_string(f.daemon_exit));
  }
  return problems;
}

void WriteFigures(std::ostream& out, const LoadFigures& f, const LoadOptions& o,
                  const std::vector<std::string>& problems) {
  const ClientTotals& m = f.main;
  const double minutes = f.main_s / 60.0;
  const auto quick = test::QuickBatch({}).config();
  out << std::fixed << std::setprecision(1);
  out << "# boicp load run (boicpd on loopback, " << o.workers << " workers, " << o.jobs
      << " job slots)\n"
      << "clients: " << o.clients << "\n"
      << "seed: " << o.seed << "\n"
      << "batch: " << o.scans_per_batch << " scans of " << o.points_per_scan << " points, preset "
      << quick.preset() << " with " << quick.random_samples() << " + " << quick.iterations()
      << " evaluations per stage\n"
      << "load_average: " << f.load_average_start << " at the start, " << f.load_average_end
      << " at the end\n"
      << "window_s: " << f.window_s << "\n"
      << "main_phase_s: " << f.main_s << " (until the last job of the window ended)\n"
      << "warmup: " << o.warmup_seconds << " s window, " << f.warmup.jobs_succeeded << " of "
      << f.warmup.jobs_submitted << " jobs completed\n"
      << "jobs_submitted: " << m.jobs_submitted << "\n"
      << "jobs_completed: " << m.jobs_succeeded << "\n"
      << "jobs_failed: " << m.jobs_failed + f.warmup.jobs_failed << "\n"
      << "jobs_unfinished: " << m.jobs_unfinished + f.warmup.jobs_unfinished << "\n"
      << "submits_rejected_queue_full: " << m.submits_rejected << "\n"
      << "uploads: " << m.uploads << " (" << m.uploads_already_present << " already present, "
      << static_cast<double>(m.upload_bytes) / (1 << 20) << " MB)\n"
      << "pairs_completed: " << m.pairs_completed << "\n"
      << "pairs_per_minute: " << static_cast<double>(m.pairs_completed) / minutes << "\n"
      << "jobs_per_minute: " << m.jobs_succeeded / minutes << "\n"
      << "rpc_calls: " << m.rpc.Calls() << "\n"
      << "rpc_errors_unexpected: " << m.rpc.UnexpectedErrors() + f.warmup.rpc.UnexpectedErrors()
      << "\n"
      << "rss_start_mb: " << f.started.rss_mb << "\n"
      << "rss_before_mb: " << f.warmed.rss_mb << " (idle after the warm-up)\n"
      << "rss_after_mb: " << f.after.rss_mb << " (idle after the run)\n"
      << "rss_peak_mb: " << f.after.peak_rss_mb << " (VmHWM)\n"
      << "rss_busy_mb:";
  for (double mb : f.busy_rss_mb) out << " " << mb;
  out << " (every " << f.busy_sample_s << " s of the main phase)\n"
      << "rss_growth_mb: " << f.after.rss_mb - f.warmed.rss_mb << " (bound " << o.max_rss_growth_mb
      << ")\n"
      << "daemon_exit_after_sigterm: " << f.daemon_exit << "\n";
  out << std::setprecision(2) << "\n# main phase, per RPC (ms; UploadScan includes its FindScans)\n"
      << std::left << std::setw(12) << "rpc" << std::right << std::setw(8) << "calls"
      << std::setw(10) << "p50" << std::setw(10) << "p99" << std::setw(10) << "max"
      << "\n";
  for (const auto& [rpc, s] : m.rpc.Summaries()) {
    out << std::left << std::setw(12) << rpc << std::right << std::setw(8) << s.calls
        << std::setw(10) << s.p50_ms << std::setw(10) << s.p99_ms << std::setw(10) << s.max_ms
        << "\n";
  }
  out << "\nresult: " << (problems.empty() ? "PASS" : "FAIL") << "\n";
  for (const std::string& problem : problems) out << "  " << problem << "\n";
}

}  // namespace boicp::load
