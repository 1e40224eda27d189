#pragma once
// Gaussian-process regression with a Matern 5/2 kernel (ARD length scales) on
// the unit box [0,1]^d. Outputs are standardised internally; predictions come
// back in the caller's units.
//
// Periodic dimensions (angles whose bounds span the full circle, so that u = 0
// and u = 1 are the same rotation) enter the kernel through the embedding
// u -> (cos 2 pi u, sin 2 pi u) / (2 pi): the kernel stays positive definite and
// the two ends of the interval are one point, so the surrogate cannot show two
// distinct optima for one rotation. A rotation vector enters as its rotation
// matrix, R / (2 sqrt2 pi): the chord between two rotations depends on their
// geodesic angle alone (2 sqrt2 sin(angle / 2)), and equals |du| for a small
// turn about an axis (kernel_inputs.hpp).
//
// Standardisation: y is centred by its mean and divided by its population
// standard deviation (1 when that is ~0), so hyperparameters are in units of
// the standardised output.

#include <random>
#include <vector>

#include <Eigen/Core>

#include "boicp/bo/kernel_inputs.hpp"

namespace boicp {

/// Matern nu = 5/2 correlation at scaled distance r >= 0:
/// (1 + sqrt(5) r + 5 r^2 / 3) exp(-sqrt(5) r).
double Matern52(double r);

struct GpHyperparameters {
  // One per input dimension, unit-box units; a rotation's second and third
  // are set to its first (KernelInputs::TiedLengthScale).
  Eigen::VectorXd length_scales;
  double signal_variance = 1.0;  // of the standardised output
  double noise_variance = 1e-4;  // of the standardised output
};

/// Bounds and effort for maximising the log marginal likelihood.
struct GpFitOptions {
  int restarts = 3;                // random starts in addition to the warm start
  int max_evaluations = 150;       // per local optimisation (NLopt LD_LBFGS)
  double min_length_scale = 0.02;  // unit-box units
  double max_length_scale = 5.0;
  double min_signal_variance = 0.05;
  double max_signal_variance = 20.0;
  double min_noise_variance = 1e-6;
  double max_noise_variance = 0.1;
};

struct GpPrediction {
  double mean = 0.0;  // posterior mean of the latent function, caller's units
  double std = 0.0;   // posterior standard deviation of the latent function (no noise)
};

class GaussianProcess {
 public:
  /// inputs[k] says how input dimension k enters the kernel.
  explicit GaussianProcess(KernelInputs inputs);

  /// Conditions on n observations: X is n x d with rows in [0,1]^d, y has n
  /// finite entries. Preconditions: n >= 1, X.cols() == inputs.dimension().
  void Condition(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const GpHyperparameters& h);

  /// Fits the hyperparameters by maximising the log marginal likelihood (with
  /// NLopt, from `warm_start` if given plus `options.restarts` random starts
  /// drawn from rng), then conditions on the data with the best ones.
  /// Without a warm start the first start is l = 0.3, signal 1, noise 1e-4.
  /// Starts are clamped into the bounds of `options`; random starts are
  /// log-uniform within them. A warm start must have d length scales.
  void Fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const GpFitOptions& options,
           std::mt19937_64& rng, const GpHyperparameters* warm_start = nullptr);

  /// Posterior of the latent function at x (size d, in [0,1]^d). Before any
  /// Condition/Fit this is the prior: mean 0, std sqrt(signal_variance).
  GpPrediction Predict(const Eigen::VectorXd& x) const;

  /// Row-wise prediction for an m x d matrix of points; same as calling
  /// Predict on each row, but with one matrix solve.
  void PredictBatch(const Eigen::MatrixXd& Xs, Eigen::VectorXd& mean, Eigen::VectorXd& std) const;

  /// Log marginal likelihood of the standardised outputs under the current
  /// hyperparameters.
  double LogMarginalLikelihood() const { return log_marginal_likelihood_; }
  const GpHyperparameters& hyperparameters() const { return hyper_; }
  int dimension() const { return inputs_.dimension(); }
  const KernelInputs& inputs() const { return inputs_; }
  /// The standardisation applied to y: y_std = (y - output_mean()) / output_scale().
  double output_mean() const { return y_mean_; }
  double output_scale() const { return y_scale_; }

 private:
  KernelInputs inputs_;
  GpHyperparameters hyper_;
  Eigen::MatrixXd X_;
  Eigen::MatrixXd scaled_features_;  // d' x n: embedded training inputs divided by length scales
  Eigen::VectorXd alpha_;            // K^-1 (y - mean) / scale, standardised
  Eigen::MatrixXd chol_lower_;       // L with K + noise I = L L^T
  double y_mean_ = 0.0, y_scale_ = 1.0;
  double log_marginal_likelihood_ = 0.0;
};

/// Log marginal likelihood of y (used as given, not standardised) for inputs X
/// (n x d, rows in [0,1]^d) under log_params = [log l_1 .. log l_d,
/// log signal_variance, log noise_variance]. If gradient is non-null it is
/// resized to d + 2 and filled with the analytic derivative with respect to
/// log_params. This is the objective GaussianProcess::Fit maximises (on the
/// standardised outputs); it is exposed so the gradient can be checked.
double GpLogMarginalLikelihood(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                               const KernelInputs& inputs, const Eigen::VectorXd& log_params,
                               Eigen::VectorXd* gradient);

}  // namespace boicp
