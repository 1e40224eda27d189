#include "evaluation_clock.hpp"

#include <algorithm>

namespace boicp::bench {

EvaluationClock::EvaluationClock() : start_(std::chrono::steady_clock::now()) {}

double EvaluationClock::Now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

RegistrationCallbacks EvaluationClock::Callbacks() {
  RegistrationCallbacks callbacks;
  callbacks.stop_requested = [this] {
    last_poll_ = Now();
    if (first_poll_ < 0.0) first_poll_ = last_poll_;
    return false;
  };
  callbacks.progress = [this](const RegistrationProgress& progress) {
    const double now = Now();
    if (progress.stage == "refine") {
      if (progress.done == 0) refine_start_ = now;
      // Every candidate refined counts, not only the first.
      if (progress.done == progress.total && refine_start_ >= 0.0) {
        split_.refine_s = now - refine_start_;
      }
    } else if (last_poll_ >= 0.0) {
      split_.icp_s += now - last_poll_;
      last_poll_ = -1.0;
    }
  };
  return callbacks;
}

EvaluationClock::Split EvaluationClock::Estimate(double wall_s) const {
  Split split = split_;
  // Setup (downsampling, index building) is everything before the first evaluation.
  const double setup = std::max(0.0, first_poll_);
  split.model_s = std::max(0.0, wall_s - setup - split.icp_s - split.refine_s);
  return split;
}

}  // namespace boicp::bench
