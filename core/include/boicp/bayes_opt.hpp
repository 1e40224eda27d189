#pragma once
// Bayesian optimisation of a black-box function on the unit box: N_r
// space-filling samples, then N expected-improvement steps on a Matern 5/2 GP.

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "boicp/acquisition.hpp"
#include "boicp/gaussian_process.hpp"

namespace boicp {

struct BayesOptOptions {
  int initial_samples = 10;  // N_r: Latin-hypercube samples before the GP guides the search
  int iterations = 20;       // N: expected-improvement steps after the initial samples
  int refit_every = 1;       // refit GP hyperparameters every k steps (warm-started between)
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

/// Called after each evaluation with the number done and the total planned.
using BayesOptProgress = std::function<void(int done, int total, double best_y)>;

/// Minimises f over [0,1]^d with d = periodic.size(). `initial_points` (rows in
/// the box, for example a prior guess) replace the first Latin-hypercube
/// samples. `stop_requested`, if set, is polled between evaluations and ends
/// the search by throwing boicp::Cancelled. Reproducible for a given seed.
/// f must return finite values.
///
/// Details: if initial_points.size() >= initial_samples only the initial
/// points are used; each is clamped into the box. Before EI step `s` the GP is
/// refitted with options.fit (warm start + restarts) when s % refit_every == 0,
/// otherwise with a single L-BFGS run warm-started from the previous
/// hyperparameters. progress is called after every evaluation. Invalid options,
/// malformed initial points and non-finite objective values (the message names
/// the 0-based evaluation index) throw boicp::InputError. One
/// std::mt19937_64(seed) drives every random choice, so a seed reproduces the
/// run bit for bit.
BayesOptResult MinimiseBayesOpt(const UnitObjective& f, const std::vector<bool>& periodic,
                                const BayesOptOptions& options, uint64_t seed,
                                const std::vector<Eigen::VectorXd>& initial_points = {},
                                const BayesOptProgress& progress = {},
                                const std::function<bool()>& stop_requested = {});

}  // namespace boicp
