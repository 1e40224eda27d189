#include "terminal_progress.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "cli_parsing.hpp"
#include "duration_text.hpp"

namespace boicp::cli {
namespace {

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

PairProgress::PairProgress(int total)
    : total_(total), started_(NowSeconds()), terminal_(StderrIsTerminal()) {}

void PairProgress::SetTotal(int total) { total_ = total; }

void PairProgress::Done(const PairResult& result, bool reused) {
  ++done_;
  if (!reused) ++registered_;
  const double elapsed = NowSeconds() - started_;
  // The rate of pairs registered in this run; reused pairs cost nothing.
  const std::string eta =
      registered_ > 0 ? FormatDuration(elapsed / registered_ * std::max(total_ - done_, 0)) : "?";
  if (terminal_) {
    constexpr int kWidth = 30;
    const int filled = total_ > 0 ? kWidth * std::min(done_, total_) / total_ : 0;
    std::fprintf(stderr, "\r[%s%s] %d/%d pairs  ETA %-8s", std::string(filled, '#').c_str(),
                 std::string(kWidth - filled, '.').c_str(), done_, total_, eta.c_str());
  } else {
    std::fprintf(stderr, "pair %s %s (%d/%d): fitness %.3f, confidence %.2f%s, %.1f s, ETA %s\n",
                 PairName(result.pair).c_str(), reused ? "reused" : "done", done_, total_,
                 result.fitness, result.confidence, result.doubtful ? " (doubtful)" : "",
                 result.runtime_s, eta.c_str());
  }
  std::fflush(stderr);
}

void PairProgress::Finish() {
  if (terminal_ && done_ > 0) std::fputc('\n', stderr);
  std::fprintf(stderr, "%d pairs (%d registered, %d reused) in %s\n", done_, registered_,
               done_ - registered_, FormatDuration(NowSeconds() - started_).c_str());
}

void TerminalProgress::PairFinished(const PairResult& pair, bool reused, const PairCounts& counts) {
  reported_ = true;
  pairs_.SetTotal(counts.total);
  pairs_.Done(pair, reused);
}

void TerminalProgress::StageStarted(MapStage /*stage*/, int /*total*/) {
  if (reported_) FinishPairs();  // `boicp merge` registers nothing and says so elsewhere
  terminal_ = StderrIsTerminal();
}

void TerminalProgress::AssemblyStep(const AssemblyProgress& p) {
  if (p.stage != MapStage::kFusing) return;
  if (terminal_) {
    std::fprintf(stderr, "\rfusing %d/%d scans", p.done, p.total);
    if (p.done == p.total) std::fputc('\n', stderr);
  } else if (p.done == p.total) {
    std::fprintf(stderr, "fused %d scans\n", p.total);
  }
}

void TerminalProgress::FinishPairs() {
  if (pairs_finished_) return;
  pairs_finished_ = true;
  pairs_.Finish();
}

}  // namespace boicp::cli
