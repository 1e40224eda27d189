#include "remote_watch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/map_pipeline.hpp"
#include "boicp/mapping/untrusted_scans.hpp"
#include "boicp/util/elapsed.hpp"
#include "cli_parsing.hpp"
#include "commands.hpp"
#include "duration_text.hpp"
#include "printable_text.hpp"

namespace boicp::cli {
namespace {

using Clock = std::chrono::steady_clock;

void PrintOutcome(const v1::Job& job) {
  const double took =
      job.finished_at() > 0.0 && job.started_at() > 0.0 ? job.finished_at() - job.started_at() : -1;
  switch (job.state()) {
    case v1::JOB_STATE_SUCCEEDED:
      std::fprintf(stderr, "job %s succeeded: %u scans, %u pairs in %s%s\n", job.job_id().c_str(),
                   job.num_scans(), job.pairs_done(), FormatDuration(took).c_str(),
                   job.pose_graph_optimised() ? ", pose graph optimised" : "");
      std::fprintf(stderr, "%s\n",
                   DoubtfulSummary(static_cast<int>(job.pairs_doubtful()),
                                   static_cast<int>(job.pairs_done()))
                       .c_str());
      for (const std::string& line : MapOutcomeLines(job)) {
        std::fprintf(stderr, "%s\n", PrintableText(line).c_str());
      }
      return;
    case v1::JOB_STATE_FAILED:
      throw JobEndedBadly("job " + job.job_id() + " failed: " + job.error());
    case v1::JOB_STATE_CANCELLED:
      throw JobEndedBadly("job " + job.job_id() + " was cancelled after " +
                          std::to_string(job.pairs_done()) + " of " +
                          std::to_string(job.pairs_total()) + " pairs");
    default:
      throw std::runtime_error("job " + job.job_id() + ": the watch ended while it was " +
                               rpc::JobStateName(job.state()));
  }
}

}  // namespace

std::vector<std::string> MapOutcomeLines(const v1::Job& job,
                                         const std::vector<std::string>& scan_names) {
  std::vector<std::string> names;
  for (const uint32_t scan : job.untrusted_scans()) {
    names.push_back(scan < scan_names.size() && !scan_names[scan].empty()
                        ? scan_names[scan]
                        : "#" + std::to_string(scan));
  }
  std::vector<std::string> lines;
  if (!names.empty()) lines.push_back(UntrustedScansLine(names, job.untrusted_left_out()));
  if (job.loop_candidates() > 0) {
    lines.push_back(LoopsClosedText(static_cast<int>(job.loops_closed()),
                                    static_cast<int>(job.loop_candidates())));
  }
  return lines;
}

std::string GapLine(uint32_t skipped) {
  return "watch fell behind: " + std::to_string(skipped) + " finished pair" +
         (skipped == 1 ? "" : "s") + " not shown (boicp show lists every pair)";
}

std::string ProgressBar(uint32_t done, uint32_t total, int width) {
  const double fraction = total > 0 ? std::min(1.0, static_cast<double>(done) / total) : 0.0;
  const int filled = static_cast<int>(fraction * width);
  return "[" + std::string(filled, '#') + std::string(width - filled, '.') + "]";
}

std::string ProgressLine(const v1::Job& job, const std::optional<v1::PairResult>& last_pair,
                         double pairs_per_min) {
  char text[256];
  std::string line = "[" + PrintableText(job.stage()) + "]";
  const bool registering = job.stage() == "registering" || job.stage() == "queued";
  if (registering || job.stage_total() == 0) {
    line +=
        " " + std::to_string(job.pairs_done()) + "/" + std::to_string(job.pairs_total()) + " pairs";
  } else {
    const char* unit = job.stage() == "fusing" ? " scans" : "";
    line += " " + std::to_string(job.stage_done()) + "/" + std::to_string(job.stage_total()) + unit;
  }
  if (registering && pairs_per_min >= 0.0) {
    std::snprintf(text, sizeof text, " | %.1f pairs/min", pairs_per_min);
    line += text;
  }
  if (job.eta_seconds() >= 0.0 && !rpc::IsTerminal(job.state())) {
    line += " | ETA " + FormatDuration(job.eta_seconds());
  }
  if (registering && last_pair) {
    std::snprintf(text, sizeof text, " | last %u->%u confidence %.2f%s", last_pair->source(),
                  last_pair->target(), last_pair->confidence(),
                  last_pair->doubtful() ? " (doubtful)" : "");
    line += text;
  }
  return line;
}

ProgressPrinter::ProgressPrinter(bool terminal, std::chrono::milliseconds min_interval)
    : terminal_(terminal), min_interval_(min_interval), start_(Clock::now()) {}

void ProgressPrinter::OnEvent(const v1::JobEvent& event) {
  const v1::Job& job = event.job();
  if (event.pairs_skipped() > 0) {
    Finish();
    std::fprintf(stderr, "%s\n", GapLine(event.pairs_skipped()).c_str());
  }
  if (!first_pairs_done_) first_pairs_done_ = job.pairs_done();
  if (event.has_pair()) last_pair_ = event.pair();
  // The rate counts only pairs finished while watching: a resumed or
  // half-done job would otherwise look faster than it is.
  const uint32_t finished_here = job.pairs_done() - std::min(job.pairs_done(), *first_pairs_done_);
  const double minutes = SecondsSince(start_) / 60.0;
  const double rate = finished_here > 0 && minutes > 0.0 ? finished_here / minutes : -1.0;
  const std::string line = ProgressLine(job, last_pair_, rate);
  if (terminal_) {
    const bool by_pairs = job.stage() == "registering" || job.stage_total() == 0;
    const std::string bar = by_pairs ? ProgressBar(job.pairs_done(), job.pairs_total())
                                     : ProgressBar(job.stage_done(), job.stage_total());
    // \033[K clears what a longer previous line left behind.
    std::fprintf(stderr, "\r%s %s\033[K", bar.c_str(), line.c_str());
    std::fflush(stderr);
    line_open_ = true;
    return;
  }
  const bool stage_changed = job.stage() != last_stage_;
  last_stage_ = job.stage();
  const bool due = !last_print_ || Clock::now() - *last_print_ >= min_interval_;
  if (!stage_changed && (!due || line == last_line_)) return;
  std::fprintf(stderr, "%s\n", line.c_str());
  std::fflush(stderr);
  last_print_ = Clock::now();
  last_line_ = line;
}

void ProgressPrinter::Finish() {
  if (line_open_) std::fputc('\n', stderr);
  line_open_ = false;
}

int FollowJob(Daemon& daemon, const std::string& job_id) {
  v1::Job job = daemon.client->GetJob(job_id);  // fails fast: unreachable daemon, unknown job
  if (!rpc::IsTerminal(job.state())) {
    ProgressPrinter printer(StderrIsTerminal());
    try {
      job = daemon.client->Watch(job_id,
                                 [&printer](const v1::JobEvent& event) { printer.OnEvent(event); });
    } catch (...) {
      printer.Finish();
      throw;
    }
    printer.Finish();
  }
  PrintOutcome(job);
  return kOk;
}

}  // namespace boicp::cli
