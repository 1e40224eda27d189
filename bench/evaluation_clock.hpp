#pragma once
// Splits a BO-ICP run's wall time into ICP evaluations, the surrogate (GP
// fitting and EI maximisation) and the final refinement, from RegisterPair's
// callbacks alone: MinimiseBayesOpt polls stop_requested right before each
// round of evaluations and RegisterPair reports progress right after them, so
// the time between a poll and the next progress report is one round of ICP
// runs (concurrent when threads > 1) plus their scores.

#include <chrono>
#include <functional>

#include "boicp/registration/bo_icp.hpp"

namespace boicp::bench {

class EvaluationClock {
 public:
  EvaluationClock();

  /// Callbacks for RegisterPair (the stop request never fires).
  RegistrationCallbacks Callbacks();

  struct Split {
    double icp_s = 0.0;     // sum of evaluation times
    double refine_s = 0.0;  // final coarse-to-fine ICP
    double model_s = 0.0;   // the rest after the first evaluation started: GP, EI, confidence
  };

  /// The split of a run that took `wall_s` in all.
  Split Estimate(double wall_s) const;

 private:
  double Now() const;

  std::chrono::steady_clock::time_point start_;
  double first_poll_ = -1.0;
  double last_poll_ = -1.0;
  double refine_start_ = -1.0;
  Split split_;
};

}  // namespace boicp::bench
