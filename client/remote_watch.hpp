#pragma once
// Following a job to its end (`boicp watch`, `boicp submit --wait`) with
// progress on stderr: one line redrawn in place on a terminal, plain
// rate-limited lines otherwise.

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "boicp/rpc/proto_convert.hpp"
#include "remote_options.hpp"

namespace boicp::cli {

/// Renders the progress of one job from its WatchJob events.
class ProgressPrinter {
 public:
  /// `terminal`: redraw one line with '\r'; else print a line per event, at
  /// most one every `min_interval` unless the stage changes.
  explicit ProgressPrinter(bool terminal,
                           std::chrono::milliseconds min_interval = std::chrono::seconds(5));
  /// Prints a GapLine first when the event carries a gap marker.
  void OnEvent(const v1::JobEvent& event);
  /// Ends the redrawn line, so that what follows starts on a fresh one.
  void Finish();

 private:
  bool terminal_;
  std::chrono::milliseconds min_interval_;
  std::chrono::steady_clock::time_point start_;
  std::optional<std::chrono::steady_clock::time_point> last_print_;
  std::optional<uint32_t> first_pairs_done_;  // at the first event, for the rate
  std::optional<v1::PairResult> last_pair_;
  std::string last_stage_, last_line_;
  bool line_open_ = false;
};

/// One line: "[registering] 5/9 pairs | 3.2 pairs/min | ETA 1m15s | last
/// 4->5 confidence 0.83" (rate and last pair while registering only; a
/// doubtful last pair is marked "(doubtful)").
/// `pairs_per_min` < 0 = unknown.
std::string ProgressLine(const v1::Job& job, const std::optional<v1::PairResult>& last_pair,
                         double pairs_per_min);

/// The gap marker of an event that says `skipped` finished pairs were merged
/// away: "watch fell behind: 12 finished pairs not shown (boicp results
/// lists every pair)".
std::string GapLine(uint32_t skipped);

/// "[#####...............]": done of total in `width` characters.
std::string ProgressBar(uint32_t done, uint32_t total, int width = 20);

/// What a succeeded job's map says beyond its pairs: the scans without a
/// trusted pair, each named by `scan_names[index]` where it has one and by
/// "#index" otherwise, and the loops closed. Lines that would be empty are
/// left out.
std::vector<std::string> MapOutcomeLines(const v1::Job& job,
                                         const std::vector<std::string>& scan_names = {});

/// Checks the job exists (a control call with a short deadline), follows
/// WatchJob until its final state with progress on stderr, and prints the
/// outcome there (on success also "N of M pairs doubtful"). Returns kOk when the job SUCCEEDED;
/// throws JobEndedBadly when it FAILED or was CANCELLED, RpcError when the daemon fails.
int FollowJob(Daemon& daemon, const std::string& job_id);

}  // namespace boicp::cli
