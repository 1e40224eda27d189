#pragma once
// Expected improvement for minimisation, and its maximisation over the unit box.

#include <random>

#include <Eigen/Core>

#include "boicp/bo/gaussian_process.hpp"

namespace boicp {

/// Closed-form expected improvement below `best` for a Gaussian prediction:
/// with z = (best - mean - xi) / std,
/// EI = (best - mean - xi) Phi(z) + std phi(z); and max(best - mean - xi, 0) when std == 0.
double ExpectedImprovement(double mean, double std, double best, double xi);

/// Probability that the latent value is below best - xi: Phi((best - mean - xi) / std).
double ProbabilityOfImprovement(double mean, double std, double best, double xi);

struct AcquisitionOptions {
  double xi = 0.01;  // exploration margin, in standard deviations of the observed outputs
  int random_candidates = 2000;    // uniform candidates scored before local refinement
  int local_starts = 5;            // best candidates refined with NLopt (bounded, derivative-free)
  int local_max_evaluations = 80;  // per local refinement
};

/// The point of [0,1]^d that maximises EI under `gp` (best = lowest observed
/// output, caller's units). Every returned coordinate lies inside the box.
/// EI is evaluated in the GP's standardised output scale, so options.xi acts as
/// options.xi * gp.output_scale() in the caller's units. Scores
/// options.random_candidates uniform points, then refines the best
/// options.local_starts of them with NLopt LN_BOBYQA. Both steps use up to
/// `threads` threads; the answer does not depend on it.
Eigen::VectorXd MaximiseExpectedImprovement(const GaussianProcess& gp, double best,
                                            const AcquisitionOptions& options, std::mt19937_64& rng,
                                            int threads = 1);

/// Largest probability of improvement over `best` among `candidates` uniform
/// points: how likely the surrogate thinks it is that an unexplored point beats
/// the incumbent. Used for the confidence figure. As for EI, xi is in standard
/// deviations of the observed outputs (xi * gp.output_scale() in caller units).
double MaxProbabilityOfImprovement(const GaussianProcess& gp, double best, double xi,
                                   int candidates, std::mt19937_64& rng);

}  // namespace boicp
