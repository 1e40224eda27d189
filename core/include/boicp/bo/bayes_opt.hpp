#pragma once
// Bayesian optimisation of a black-box function on the unit box: N_r
// space-filling samples, then N expected-improvement steps on a Matern 5/2 GP,
// proposed and evaluated q at a time.

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "boicp/bo/acquisition.hpp"
#include "boicp/bo/gaussian_process.hpp"

namespace boicp {

struct BayesOptOptions {
  int initial_samples = 10;  // N_r: Latin-hypercube samples before the GP guides the search
  int iterations = 20;       // N: expected-improvement steps after the initial samples
  // Evaluations between refits of the GP hyperparameters (one L-BFGS run from
  // the previous values); in between, the GP is only conditioned on the new
  // data with the hyperparameters held.
  int refit_every = 5;
  // q: points proposed per round (kriging believer: each proposal is added to
  // the GP at its predicted mean before the next is chosen) and evaluated
  // together. The answer depends on q, never on `threads`.
  int batch_size = 2;
  // Evaluations of one round run at once (the objective must be thread-safe),
  // and the acquisition scores its candidates on as many threads.
  int threads = 1;
  GpFitOptions fit;
  AcquisitionOptions acquisition;
  int confidence_candidates = 2000;  // points scanned for MaxProbabilityOfImprovement at the end
};

struct BayesOptSample {
  Eigen::VectorXd x;  // in [0,1]^d
  double y = 0.0;     // objective value
};

struct BayesOptResult {
  Eigen::VectorXd best_x;
  double best_y = 0.0;
  size_t best_index = 0;                // into history
  std::vector<BayesOptSample> history;  // every evaluation, in order
  double gp_mean_at_best = 0.0;         // final GP posterior at best_x, objective units
  double gp_std_at_best = 0.0;
  double probability_better = 0.0;    // MaxProbabilityOfImprovement at the end, in [0,1]
  GpHyperparameters hyperparameters;  // final fit
};

using UnitObjective = std::function<double(const Eigen::VectorXd& unit_x)>;

/// An objective told the value it has to beat to matter: the best value found
/// before the current round (+infinity in the first). Below it, it must return
/// f(x); once it knows it cannot get below, it may stop early and return any
/// value above it. Called concurrently when options.threads > 1.
using BoundedObjective = std::function<double(const Eigen::VectorXd& unit_x, double incumbent)>;

/// Called after each evaluation with the number done and the total planned.
using BayesOptProgress = std::function<void(int done, int total, double best_y)>;

/// Decides after a round whether a search has learned enough to end early:
/// told the history so far (every evaluation, in order). Only asked once the
/// initial design has been evaluated.
using BayesOptEnough = std::function<bool(const std::vector<BayesOptSample>& history)>;

/// What a caller may add to a search beyond its options.
struct BayesOptHooks {
  BayesOptProgress progress;
  std::function<bool()> stop_requested;
  BayesOptEnough enough;  // empty: the whole budget
  /// The history of an earlier run of this same search (objective, box,
  /// options, initial points and seed) that `enough` ended: those
  /// evaluations count as done and are not repeated, and the search goes on
  /// to the full budget from there.
  std::vector<BayesOptSample> resume;
};

/// Minimises f over [0,1]^d with d = inputs.dimension(). Evaluations run in
/// rounds of options.batch_size points (the initial design too). `initial_points` (rows in
/// the box, for example a prior guess) replace the first Latin-hypercube
/// samples; a rotation's coordinates in those samples are spread uniformly
/// over all rotations instead (UniformRotations). `stop_requested`, if set, is polled between
/// evaluations and ends the search by throwing boicp::Cancelled. Reproducible for a given seed. f
/// must return finite values.
///
/// Details: if initial_points.size() >= initial_samples only the initial
/// points are used; each is clamped into the box. The first and the final GP
/// fit use options.fit (warm start + restarts). Before an EI round the
/// hyperparameters are refitted by one L-BFGS run from the previous ones when
/// refit_every evaluations have come in since the last fit, and held (the GP
/// only conditioned on the new data) otherwise. progress is called after every evaluation, in
/// proposal order, once its whole round has been evaluated. Invalid options, malformed initial
/// points and non-finite objective values (the message names the 0-based evaluation index) throw
/// boicp::InputError. One std::mt19937_64(seed) drives every random choice, so a seed reproduces
/// the run bit for bit.
BayesOptResult MinimiseBayesOpt(const BoundedObjective& f, const KernelInputs& inputs,
                                const BayesOptOptions& options, uint64_t seed,
                                const std::vector<Eigen::VectorXd>& initial_points = {},
                                const BayesOptProgress& progress = {},
                                const std::function<bool()>& stop_requested = {});

/// The same with every hook: an early end (hooks.enough) and the
/// continuation of a search that ended early (hooks.resume).
BayesOptResult MinimiseBayesOpt(const BoundedObjective& f, const KernelInputs& inputs,
                                const BayesOptOptions& options, uint64_t seed,
                                const std::vector<Eigen::VectorXd>& initial_points,
                                const BayesOptHooks& hooks);

/// The same for an objective that always returns f(x).
BayesOptResult MinimiseBayesOpt(const UnitObjective& f, const KernelInputs& inputs,
                                const BayesOptOptions& options, uint64_t seed,
                                const std::vector<Eigen::VectorXd>& initial_points = {},
                                const BayesOptProgress& progress = {},
                                const std::function<bool()>& stop_requested = {});

}  // namespace boicp
