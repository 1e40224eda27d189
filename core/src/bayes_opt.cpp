#include "boicp/bayes_opt.hpp"

#include <cmath>
#include <random>
#include <sstream>
#include <string>

#include "boicp/sampling.hpp"
#include "boicp/types.hpp"

namespace boicp {
namespace {

void Require(bool ok, const std::string& message) {
  if (!ok) throw InputError("BayesOptOptions: " + message);
}

void ValidateOptions(const BayesOptOptions& o, const std::vector<bool>& periodic) {
  Require(!periodic.empty(), "the search space needs at least one dimension (periodic is empty)");
  Require(o.initial_samples >= 1,
          "initial_samples must be >= 1, got " + std::to_string(o.initial_samples));
  Require(o.iterations >= 0, "iterations must be >= 0, got " + std::to_string(o.iterations));
  Require(o.refit_every >= 1, "refit_every must be >= 1, got " + std::to_string(o.refit_every));
  Require(o.confidence_candidates >= 1,
          "confidence_candidates must be >= 1, got " + std::to_string(o.confidence_candidates));
  // Checked here too so a bad config fails before the first (costly) evaluation.
  const AcquisitionOptions& a = o.acquisition;
  Require(a.random_candidates >= 1 && a.local_starts >= 0 && a.local_max_evaluations >= 1 &&
              std::isfinite(a.xi),
          "acquisition needs random_candidates >= 1, local_starts >= 0, "
          "local_max_evaluations >= 1 and a finite xi");
  const GpFitOptions& g = o.fit;
  Require(g.restarts >= 0 && g.max_evaluations >= 1 && 0 < g.min_length_scale &&
              g.min_length_scale <= g.max_length_scale && 0 < g.min_signal_variance &&
              g.min_signal_variance <= g.max_signal_variance && 0 < g.min_noise_variance &&
              g.min_noise_variance <= g.max_noise_variance,
          "fit needs restarts >= 0, max_evaluations >= 1 and 0 < min <= max for every bound");
}

// initial_points (clamped into the box) followed by Latin-hypercube rows up to
// initial_samples in total.
std::vector<Eigen::VectorXd> InitialDesign(const std::vector<Eigen::VectorXd>& initial_points,
                                           int initial_samples, int d, std::mt19937_64& rng) {
  std::vector<Eigen::VectorXd> design;
  for (size_t i = 0; i < initial_points.size(); ++i) {
    const Eigen::VectorXd& x = initial_points[i];
    if (x.size() != d || !x.allFinite()) {
      throw InputError("BayesOpt: initial point " + std::to_string(i) + " must have " +
                       std::to_string(d) + " finite coordinates, got " + std::to_string(x.size()));
    }
    design.push_back(x.cwiseMax(0.0).cwiseMin(1.0));
  }
  const int missing = initial_samples - static_cast<int>(design.size());
  if (missing > 0) {
    const Eigen::MatrixXd lhs = LatinHypercube(missing, d, rng);
    for (int i = 0; i < missing; ++i) design.push_back(lhs.row(i).transpose());
  }
  return design;
}

// Runs the objective and keeps history, incumbent and progress reporting.
class Evaluator {
 public:
  Evaluator(const UnitObjective& f, int total, const BayesOptProgress& progress,
            const std::function<bool()>& stop_requested, BayesOptResult& result)
      : f_(f), total_(total), progress_(progress), stop_(stop_requested), result_(result) {
    result_.history.reserve(static_cast<size_t>(total));
  }

  void Evaluate(const Eigen::VectorXd& x) {
    if (stop_ && stop_()) throw Cancelled();
    const double y = f_(x);
    const size_t index = result_.history.size();
    if (!std::isfinite(y)) {
      std::ostringstream message;
      message << "BayesOpt: objective returned non-finite value " << y << " at evaluation " << index
              << " (0-based)";
      throw InputError(message.str());
    }
    result_.history.push_back({x, y});
    if (index == 0 || y < result_.best_y) {
      result_.best_y = y;
      result_.best_x = x;
      result_.best_index = index;
    }
    if (progress_) progress_(static_cast<int>(index) + 1, total_, result_.best_y);
  }

 private:
  const UnitObjective& f_;
  int total_;
  const BayesOptProgress& progress_;
  const std::function<bool()>& stop_;
  BayesOptResult& result_;
};

void HistoryAsData(const std::vector<BayesOptSample>& history, int d, Eigen::MatrixXd& X,
                   Eigen::VectorXd& y) {
  const auto n = static_cast<Eigen::Index>(history.size());
  X.resize(n, d);
  y.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    X.row(i) = history[static_cast<size_t>(i)].x.transpose();
    y(i) = history[static_cast<size_t>(i)].y;
  }
}

// A full refit runs the multi-start likelihood search; between refits a single
// L-BFGS run from the previous hyperparameters (restarts = 0) tracks the new
// data at a fraction of the cost.
void FitSurrogate(GaussianProcess& gp, const std::vector<BayesOptSample>& history,
                  const GpFitOptions& fit, bool full_refit, std::mt19937_64& rng,
                  const GpHyperparameters* warm_start) {
  Eigen::MatrixXd X;
  Eigen::VectorXd y;
  HistoryAsData(history, gp.dimension(), X, y);
  GpFitOptions options = fit;
  if (!full_refit) options.restarts = 0;
  gp.Fit(X, y, options, rng, warm_start);
}

}  // namespace

BayesOptResult MinimiseBayesOpt(const UnitObjective& f, const std::vector<bool>& periodic,
                                const BayesOptOptions& options, uint64_t seed,
                                const std::vector<Eigen::VectorXd>& initial_points,
                                const BayesOptProgress& progress,
                                const std::function<bool()>& stop_requested) {
  ValidateOptions(options, periodic);
  const auto d = static_cast<int>(periodic.size());
  std::mt19937_64 rng(seed);
  const std::vector<Eigen::VectorXd> design =
      InitialDesign(initial_points, options.initial_samples, d, rng);
  const int total = static_cast<int>(design.size()) + options.iterations;

  BayesOptResult result;
  Evaluator evaluator(f, total, progress, stop_requested, result);
  for (const Eigen::VectorXd& x : design) evaluator.Evaluate(x);

  GaussianProcess gp(periodic);
  GpHyperparameters last;
  bool have_last = false;
  for (int step = 0; step < options.iterations; ++step) {
    FitSurrogate(gp, result.history, options.fit, step % options.refit_every == 0, rng,
                 have_last ? &last : nullptr);
    last = gp.hyperparameters();
    have_last = true;
    evaluator.Evaluate(MaximiseExpectedImprovement(gp, result.best_y, options.acquisition, rng));
  }

  FitSurrogate(gp, result.history, options.fit, true, rng, have_last ? &last : nullptr);
  const GpPrediction at_best = gp.Predict(result.best_x);
  result.gp_mean_at_best = at_best.mean;
  result.gp_std_at_best = at_best.std;
  result.probability_better = MaxProbabilityOfImprovement(gp, result.best_y, options.acquisition.xi,
                                                          options.confidence_candidates, rng);
  result.hyperparameters = gp.hyperparameters();
  return result;
}

}  // namespace boicp
