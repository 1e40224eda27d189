#include "boicp/bo/bayes_opt.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "boicp/bo/sampling.hpp"
#include "boicp/util/parallel_for.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

void RequireValidOptions(bool ok, const std::string& message) {
  if (!ok) throw InputError("BayesOptOptions: " + message);
}

void ValidateOptions(const BayesOptOptions& o, const KernelInputs& inputs) {
  RequireValidOptions(!inputs.empty(),
                      "the search space needs at least one dimension (inputs is empty)");
  RequireValidOptions(o.initial_samples >= 1,
                      "initial_samples must be >= 1, got " + std::to_string(o.initial_samples));
  RequireValidOptions(o.iterations >= 0,
                      "iterations must be >= 0, got " + std::to_string(o.iterations));
  RequireValidOptions(o.refit_every >= 1,
                      "refit_every must be >= 1, got " + std::to_string(o.refit_every));
  RequireValidOptions(o.batch_size >= 1,
                      "batch_size must be >= 1, got " + std::to_string(o.batch_size));
  RequireValidOptions(o.threads >= 1, "threads must be >= 1, got " + std::to_string(o.threads));
  RequireValidOptions(o.confidence_candidates >= 1, "confidence_candidates must be >= 1, got " +
                                                        std::to_string(o.confidence_candidates));
  // Checked here too so a bad config fails before the first (costly) evaluation.
  const AcquisitionOptions& a = o.acquisition;
  RequireValidOptions(a.random_candidates >= 1 && a.local_starts >= 0 &&
                          a.local_max_evaluations >= 1 && std::isfinite(a.xi),
                      "acquisition needs random_candidates >= 1, local_starts >= 0, "
                      "local_max_evaluations >= 1 and a finite xi");
  const GpFitOptions& g = o.fit;
  RequireValidOptions(
      g.restarts >= 0 && g.max_evaluations >= 1 && 0 < g.min_length_scale &&
          g.min_length_scale <= g.max_length_scale && 0 < g.min_signal_variance &&
          g.min_signal_variance <= g.max_signal_variance && 0 < g.min_noise_variance &&
          g.min_noise_variance <= g.max_noise_variance,
      "fit needs restarts >= 0, max_evaluations >= 1 and 0 < min <= max for every bound");
}

// initial_points (clamped into the box) followed by Latin-hypercube rows up to
// initial_samples in total, whose rotation coordinates are uniform rotations.
std::vector<Eigen::VectorXd> InitialDesign(const std::vector<Eigen::VectorXd>& initial_points,
                                           int initial_samples, const KernelInputs& inputs,
                                           std::mt19937_64& rng) {
  const int d = inputs.dimension();
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
    Eigen::MatrixXd lhs = LatinHypercube(missing, d, rng);
    for (int k = 0; k < d; ++k) {
      if (inputs.StartsRotation(k)) lhs.middleCols<3>(k) = UniformRotations(missing, rng);
    }
    for (int i = 0; i < missing; ++i) design.push_back(lhs.row(i).transpose());
  }
  return design;
}

// Runs the objective a round at a time and keeps history, incumbent and
// progress reporting.
class Evaluator {
 public:
  Evaluator(const BoundedObjective& f, int total, int threads, const BayesOptProgress& progress,
            const std::function<bool()>& stop_requested, BayesOptResult& result)
      : f_(f),
        total_(total),
        threads_(threads),
        progress_(progress),
        stop_(stop_requested),
        result_(result) {
    result_.history.reserve(static_cast<size_t>(total));
  }

  // Takes over the evaluations of an earlier run of the same search, without
  // reporting them again.
  void Restore(const std::vector<BayesOptSample>& done) {
    for (const BayesOptSample& sample : done) {
      if (result_.history.empty() || sample.y < result_.best_y) {
        result_.best_y = sample.y;
        result_.best_x = sample.x;
        result_.best_index = result_.history.size();
      }
      result_.history.push_back(sample);
    }
  }

  // Every point of a round is told the same incumbent, so the values do not
  // depend on how many of them run at once.
  void EvaluateRound(const std::vector<Eigen::VectorXd>& xs) {
    if (stop_ && stop_()) throw Cancelled();
    const double incumbent =
        result_.history.empty() ? std::numeric_limits<double>::infinity() : result_.best_y;
    std::vector<double> values(xs.size());
    ParallelFor(xs.size(), threads_, [&](size_t i) { values[i] = f_(xs[i], incumbent); });
    for (size_t i = 0; i < xs.size(); ++i) Record(xs[i], values[i]);
  }

 private:
  void Record(const Eigen::VectorXd& x, double y) {
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

  const BoundedObjective& f_;
  int total_;
  int threads_;
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

// Keeps the surrogate up to date at three prices: a multi-start fit of the
// hyperparameters (the first and the final fit), a single L-BFGS run from the
// previous hyperparameters (every refit_every evaluations), or only
// conditioning on the new data with them held, which at the n <= a few hundred
// of a search is one small Cholesky factorisation.
enum class SurrogateUpdate { kFullFit, kWarmFit, kCondition };

void UpdateSurrogate(GaussianProcess& gp, const std::vector<BayesOptSample>& history,
                     const GpFitOptions& fit, SurrogateUpdate update, std::mt19937_64& rng,
                     const GpHyperparameters* previous) {
  Eigen::MatrixXd X;
  Eigen::VectorXd y;
  HistoryAsData(history, gp.dimension(), X, y);
  if (previous == nullptr || update == SurrogateUpdate::kFullFit) {
    gp.Fit(X, y, fit, rng, previous);
  } else if (update == SurrogateUpdate::kWarmFit) {
    GpFitOptions warm = fit;
    warm.restarts = 0;
    gp.Fit(X, y, warm, rng, previous);
  } else {
    gp.Condition(X, y, *previous);
  }
}

// Kriging believer: after each proposal the GP (hyperparameters held) is told
// that the objective there equals its own prediction, which flattens EI around
// it so the next proposal goes elsewhere. q = 1 is plain expected improvement.
std::vector<Eigen::VectorXd> ProposeRound(GaussianProcess gp,
                                          const std::vector<BayesOptSample>& history, double best,
                                          int q, const AcquisitionOptions& acquisition, int threads,
                                          std::mt19937_64& rng) {
  Eigen::MatrixXd X;
  Eigen::VectorXd y;
  HistoryAsData(history, gp.dimension(), X, y);
  std::vector<Eigen::VectorXd> proposals;
  for (int j = 0; j < q; ++j) {
    proposals.push_back(MaximiseExpectedImprovement(gp, best, acquisition, rng, threads));
    if (j + 1 == q) break;
    const double believed = gp.Predict(proposals.back()).mean;
    X.conservativeResize(X.rows() + 1, Eigen::NoChange);
    X.row(X.rows() - 1) = proposals.back().transpose();
    y.conservativeResize(y.size() + 1);
    y(y.size() - 1) = believed;
    best = std::min(best, believed);
    gp.Condition(X, y, gp.hyperparameters());
  }
  return proposals;
}

}  // namespace

BayesOptResult MinimiseBayesOpt(const BoundedObjective& f, const KernelInputs& inputs,
                                const BayesOptOptions& options, uint64_t seed,
                                const std::vector<Eigen::VectorXd>& initial_points,
                                const BayesOptHooks& hooks) {
  ValidateOptions(options, inputs);
  std::mt19937_64 rng(seed);
  const std::vector<Eigen::VectorXd> design =
      InitialDesign(initial_points, options.initial_samples, inputs, rng);
  const int total = static_cast<int>(design.size()) + options.iterations;
  const auto q = static_cast<size_t>(options.batch_size);

  BayesOptResult result;
  Evaluator evaluator(f, total, options.threads, hooks.progress, hooks.stop_requested, result);
  evaluator.Restore(hooks.resume);
  const auto enough = [&] { return hooks.enough && hooks.enough(result.history); };
  for (size_t first = result.history.size(); first < design.size(); first += q) {
    evaluator.EvaluateRound(
        {design.begin() + static_cast<std::ptrdiff_t>(first),
         design.begin() + static_cast<std::ptrdiff_t>(std::min(first + q, design.size()))});
  }

  GaussianProcess gp(inputs);
  GpHyperparameters fitted;
  bool have_fit = false;
  int since_fit = 0;
  const int resumed_iterations =
      std::max(0, static_cast<int>(result.history.size()) - static_cast<int>(design.size()));
  for (int done = resumed_iterations; done < options.iterations && !enough();) {
    const int round = std::min(options.batch_size, options.iterations - done);
    const bool refit = !have_fit || since_fit >= options.refit_every;
    UpdateSurrogate(gp, result.history, options.fit,
                    refit ? SurrogateUpdate::kWarmFit : SurrogateUpdate::kCondition, rng,
                    have_fit ? &fitted : nullptr);
    if (refit) since_fit = 0;
    fitted = gp.hyperparameters();
    have_fit = true;
    evaluator.EvaluateRound(ProposeRound(gp, result.history, result.best_y, round,
                                         options.acquisition, options.threads, rng));
    done += round;
    since_fit += round;
  }

  UpdateSurrogate(gp, result.history, options.fit, SurrogateUpdate::kFullFit, rng,
                  have_fit ? &fitted : nullptr);
  const GpPrediction at_best = gp.Predict(result.best_x);
  result.gp_mean_at_best = at_best.mean;
  result.gp_std_at_best = at_best.std;
  result.probability_better = MaxProbabilityOfImprovement(gp, result.best_y, options.acquisition.xi,
                                                          options.confidence_candidates, rng);
  result.hyperparameters = gp.hyperparameters();
  return result;
}

BayesOptResult MinimiseBayesOpt(const BoundedObjective& f, const KernelInputs& inputs,
                                const BayesOptOptions& options, uint64_t seed,
                                const std::vector<Eigen::VectorXd>& initial_points,
                                const BayesOptProgress& progress,
                                const std::function<bool()>& stop_requested) {
  return MinimiseBayesOpt(f, inputs, options, seed, initial_points,
                          BayesOptHooks{progress, stop_requested, {}, {}});
}

BayesOptResult MinimiseBayesOpt(const UnitObjective& f, const KernelInputs& inputs,
                                const BayesOptOptions& options, uint64_t seed,
                                const std::vector<Eigen::VectorXd>& initial_points,
                                const BayesOptProgress& progress,
                                const std::function<bool()>& stop_requested) {
  const BoundedObjective unbounded = [&f](const Eigen::VectorXd& x, double) { return f(x); };
  return MinimiseBayesOpt(unbounded, inputs, options, seed, initial_points, progress,
                          stop_requested);
}

}  // namespace boicp
