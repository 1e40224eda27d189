#include "boicp/bo/gaussian_process.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <nlopt.hpp>

#include "boicp/bo/sampling.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSqrt5 = 2.23606797749978969641;
constexpr double kLog2Pi = 1.83787706640934548356;

// Returned instead of the likelihood when no jitter makes the covariance
// positive definite: finite, so the line search backs off instead of failing.
constexpr double kHopelessLogLikelihood = -1e300;

// Jitter ladder for Cholesky, relative to the signal variance.
constexpr double kFirstJitter = 1e-10;
constexpr double kMaxFitJitter = 1e-4;
// Condition must always succeed, so it climbs further as a last resort.
constexpr double kMaxConditionJitter = 1.0;

// A chord of R / (2 sqrt2 pi) is |du| for a small turn about one axis, whose
// angle is 2 pi du.
constexpr double kRotationChordScale = 1.0 / (2.0 * 1.41421356237309504880 * kPi);

int EmbeddedWidth(const KernelInputs& inputs) {
  int width = 0;
  for (int k = 0; k < inputs.dimension(); ++k) width += inputs.EmbeddedWidth(k);
  return width;
}

// Maps rows of X (n x d) to columns of a d' x n matrix in which the squared
// distance along input dimension k is the plain sum of squares over k's
// columns, each divided by length_scales[k]^2. Periodic u becomes
// (cos 2 pi u, sin 2 pi u) / (2 pi): a chord that equals |du| for small du and
// makes u = 0 and u = 1 the same point. A rotation's three coordinates become
// the nine entries of its matrix, under the first one's length scale.
Eigen::MatrixXd ScaledFeatures(const Eigen::MatrixXd& X, const KernelInputs& inputs,
                               const Eigen::VectorXd& length_scales) {
  const int d = inputs.dimension();
  Eigen::MatrixXd F(EmbeddedWidth(inputs), X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    int c = 0;
    for (int k = 0; k < d; ++k) {
      if (inputs.EmbeddedWidth(k) == 0) continue;
      const double inv_l = 1.0 / length_scales(k);
      const double u = X(i, k);
      switch (inputs[k]) {
        case InputKind::kPeriodic:
          F(c++, i) = std::cos(2.0 * kPi * u) / (2.0 * kPi) * inv_l;
          F(c++, i) = std::sin(2.0 * kPi * u) / (2.0 * kPi) * inv_l;
          break;
        case InputKind::kRotation: {
          const Eigen::Matrix3d R = RotationFromUnit(X.row(i).segment<3>(k).transpose());
          F.col(i).segment<9>(c) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(R.data()) *
                                   (kRotationChordScale * inv_l);
          c += 9;
          break;
        }
        case InputKind::kLinear:
          F(c++, i) = u * inv_l;
          break;
      }
    }
  }
  return F;
}

// Per-dimension squared distances D_k(i, j) for all pairs i > j, in the order
// (j = 0: i = 1..n-1), (j = 1: i = 2..n-1), ...; P x d with P = n(n-1)/2.
// Computed once per Fit: the likelihood then only needs r^2 = D * l^-2.
Eigen::MatrixXd PairwiseSquaredDistances(const Eigen::MatrixXd& X, const KernelInputs& inputs) {
  const int d = inputs.dimension();
  const Eigen::Index n = X.rows();
  const Eigen::MatrixXd F = ScaledFeatures(X, inputs, Eigen::VectorXd::Ones(d));
  Eigen::MatrixXd D(n * (n - 1) / 2, d);
  Eigen::Index p = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = j + 1; i < n; ++i, ++p) {
      int c = 0;
      for (int k = 0; k < d; ++k) {
        const int width = inputs.EmbeddedWidth(k);
        D(p, k) = (F.col(i).segment(c, width) - F.col(j).segment(c, width)).squaredNorm();
        c += width;
      }
    }
  }
  return D;
}

struct LogParams {
  Eigen::VectorXd inv_l2;  // 1 / l_k^2
  double signal = 1.0;
  double noise = 1e-4;
};

LogParams Unpack(const Eigen::VectorXd& theta) {
  const Eigen::Index d = theta.size() - 2;
  LogParams p;
  p.inv_l2 = (-2.0 * theta.head(d).array()).exp().matrix();
  p.signal = std::exp(theta(d));
  p.noise = std::exp(theta(d + 1));
  return p;
}

Eigen::VectorXd Pack(const GpHyperparameters& h) {
  const Eigen::Index d = h.length_scales.size();
  Eigen::VectorXd theta(d + 2);
  theta.head(d) = h.length_scales.array().log().matrix();
  theta(d) = std::log(h.signal_variance);
  theta(d + 1) = std::log(h.noise_variance);
  return theta;
}

GpHyperparameters UnpackHyperparameters(const Eigen::VectorXd& theta) {
  const Eigen::Index d = theta.size() - 2;
  GpHyperparameters h;
  h.length_scales = theta.head(d).array().exp().matrix();
  h.signal_variance = std::exp(theta(d));
  h.noise_variance = std::exp(theta(d + 1));
  return h;
}

// Left-looking Cholesky of the lower triangle of A, in place. Written out
// because Eigen's blocked LLT allocates GEMM workspace on every call, and on
// small matrices that heap traffic costs more than the factorisation.
bool CholeskyInPlace(Eigen::MatrixXd& A) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::Index below = n - j;
    if (j > 0) {
      A.col(j).tail(below).noalias() -= A.block(j, 0, below, j) * A.row(j).head(j).transpose();
    }
    const double pivot = A(j, j);
    if (!(pivot > 0.0) || !std::isfinite(pivot)) return false;
    const double l = std::sqrt(pivot);
    A(j, j) = l;
    A.col(j).tail(below - 1) /= l;
  }
  return true;
}

// K = L L^T into L, adding jitter * signal to K's diagonal (1e-10, 1e-9, ...
// up to max_jitter) when rounding makes K numerically indefinite.
bool CholeskyWithJitter(Eigen::MatrixXd& K, double signal, double max_jitter, Eigen::MatrixXd& L) {
  L = K;
  if (CholeskyInPlace(L)) return true;
  double added = 0.0;
  for (double jitter = kFirstJitter; jitter <= max_jitter * (1.0 + 1e-9); jitter *= 10.0) {
    K.diagonal().array() += (jitter - added) * signal;
    added = jitter;
    L = K;
    if (CholeskyInPlace(L)) return true;
  }
  return false;
}

// Everything the likelihood needs for one data set, allocated once per Fit so
// that an evaluation does no large heap allocation.
class MarginalLikelihood {
 public:
  MarginalLikelihood(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const KernelInputs& inputs)
      : y_(y),
        D_(PairwiseSquaredDistances(X, inputs)),
        K_(y.size(), y.size()),
        L_(y.size(), y.size()),
        k_pair_(D_.rows()),
        dk_pair_(D_.rows()),
        w_pair_(D_.rows()) {}

  // log p(y | theta) = -y^T alpha / 2 - sum log L_ii - n log(2 pi) / 2, and
  // d/dtheta = tr((alpha alpha^T - K^-1) dK/dtheta) / 2.
  double Evaluate(const Eigen::VectorXd& theta, Eigen::VectorXd* gradient, double max_jitter) {
    const LogParams p = Unpack(theta);
    BuildCovariance(p);
    factorised_ = CholeskyWithJitter(K_, p.signal, max_jitter, L_);
    if (!factorised_) {
      if (gradient != nullptr) gradient->setZero(theta.size());
      return kHopelessLogLikelihood;
    }
    alpha_ = y_;
    L_.triangularView<Eigen::Lower>().solveInPlace(alpha_);
    const double y_quad = alpha_.squaredNorm();  // y^T K^-1 y = |L^-1 y|^2
    L_.triangularView<Eigen::Lower>().adjoint().solveInPlace(alpha_);
    const double log_det_half = L_.diagonal().array().log().sum();
    const auto n = static_cast<double>(y_.size());
    const double lml = -0.5 * y_quad - log_det_half - 0.5 * n * kLog2Pi;
    if (!std::isfinite(lml)) {
      if (gradient != nullptr) gradient->setZero(theta.size());
      return kHopelessLogLikelihood;
    }
    if (gradient != nullptr) Gradient(p, gradient);
    return lml;
  }

  bool factorised() const { return factorised_; }
  const Eigen::MatrixXd& cholesky_lower() const { return L_; }  // upper triangle unspecified
  const Eigen::VectorXd& alpha() const { return alpha_; }

 private:
  // Lower triangle of K = signal * Matern52(r) + noise I, keeping per pair
  // k_ij and the common factor of dk/dlog l_k:
  // signal (5/3)(1 + sqrt5 r) exp(-sqrt5 r), which has no 1/r, so r = 0 is safe.
  void BuildCovariance(const LogParams& p) {
    const Eigen::Index n = y_.size();
    Eigen::Index q = 0;
    for (Eigen::Index j = 0; j < n; ++j) {
      K_(j, j) = p.signal + p.noise;
      for (Eigen::Index i = j + 1; i < n; ++i, ++q) {
        const double r = std::sqrt(D_.row(q).dot(p.inv_l2));
        const double e = std::exp(-kSqrt5 * r);
        k_pair_(q) = p.signal * (1.0 + kSqrt5 * r + (5.0 / 3.0) * r * r) * e;
        dk_pair_(q) = p.signal * (5.0 / 3.0) * (1.0 + kSqrt5 * r) * e;
        K_(i, j) = k_pair_(q);
      }
    }
  }

  // L^-1 by forward substitution on the identity, one row at a time: once row
  // k is final it is eliminated from the rows below with one rank-1 update.
  void InvertCholeskyFactor() {
    const Eigen::Index n = y_.size();
    L_inv_.setIdentity(n, n);
    for (Eigen::Index k = 0; k < n; ++k) {
      L_inv_.row(k).head(k + 1) /= L_(k, k);
      if (k + 1 < n) {
        L_inv_.block(k + 1, 0, n - k - 1, k + 1).noalias() -=
            L_.col(k).tail(n - k - 1) * L_inv_.row(k).head(k + 1);
      }
    }
  }

  // W = alpha alpha^T - K^-1 is symmetric and every dK is zero on the
  // diagonal except for signal and noise, so the length-scale traces are
  // sums over pairs i > j counted twice.
  void Gradient(const LogParams& p, Eigen::VectorXd* gradient) {
    InvertCholeskyFactor();
    const Eigen::Index n = y_.size();
    const Eigen::Index d = D_.cols();
    Eigen::Index q = 0;
    double w_k_pairs = 0.0;
    double k_inv_trace = 0.0;
    // K^-1 = L^-T L^-1 and L^-1 is lower triangular, so (K^-1)_ij for i >= j
    // is the dot product of columns i and j of L^-1 from row i down.
    for (Eigen::Index j = 0; j < n; ++j) {
      k_inv_trace += L_inv_.col(j).tail(n - j).squaredNorm();
      for (Eigen::Index i = j + 1; i < n; ++i, ++q) {
        const double k_inv_ij = L_inv_.col(i).tail(n - i).dot(L_inv_.col(j).tail(n - i));
        w_pair_(q) = alpha_(i) * alpha_(j) - k_inv_ij;
        w_k_pairs += w_pair_(q) * k_pair_(q);
      }
    }
    const double w_trace = alpha_.squaredNorm() - k_inv_trace;
    gradient->resize(d + 2);
    gradient->head(d) = (D_.transpose() * w_pair_.cwiseProduct(dk_pair_)).cwiseProduct(p.inv_l2);
    (*gradient)(d) = 0.5 * p.signal * w_trace + w_k_pairs;
    (*gradient)(d + 1) = 0.5 * p.noise * w_trace;
  }

  const Eigen::VectorXd& y_;
  const Eigen::MatrixXd D_;
  Eigen::MatrixXd K_, L_, L_inv_;
  Eigen::VectorXd k_pair_, dk_pair_, w_pair_, alpha_;
  bool factorised_ = false;
};

void CheckData(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, int d) {
  if (X.rows() < 1 || X.rows() != y.size() || X.cols() != d) {
    throw InputError("GaussianProcess: need n >= 1 rows of dimension " + std::to_string(d) +
                     " and n outputs, got X " + std::to_string(X.rows()) + " x " +
                     std::to_string(X.cols()) + " and y of size " + std::to_string(y.size()));
  }
  if (!X.allFinite() || !y.allFinite()) {
    throw InputError("GaussianProcess: inputs and outputs must be finite");
  }
}

void CheckFitOptions(const GpFitOptions& o) {
  const bool ok = o.restarts >= 0 && o.max_evaluations >= 1 && 0 < o.min_length_scale &&
                  o.min_length_scale <= o.max_length_scale && 0 < o.min_signal_variance &&
                  o.min_signal_variance <= o.max_signal_variance && 0 < o.min_noise_variance &&
                  o.min_noise_variance <= o.max_noise_variance;
  if (!ok) {
    throw InputError(
        "GpFitOptions: need restarts >= 0, max_evaluations >= 1 and 0 < min <= max for every "
        "length-scale / signal / noise bound");
  }
}

struct Standardisation {
  double mean = 0.0;
  double scale = 1.0;
};

// Population mean and standard deviation; a (numerically) constant y keeps
// scale 1 so the standardised outputs stay finite.
Standardisation Standardise(const Eigen::VectorXd& y) {
  Standardisation s;
  s.mean = y.mean();
  const double sd = std::sqrt((y.array() - s.mean).square().mean());
  s.scale = sd > 1e-12 * std::max(1.0, std::abs(s.mean)) ? sd : 1.0;
  return s;
}

// Box for theta = [log l, log signal, log noise].
void LogBounds(const GpFitOptions& o, int d, Eigen::VectorXd& lower, Eigen::VectorXd& upper) {
  lower.resize(d + 2);
  upper.resize(d + 2);
  lower.head(d).setConstant(std::log(o.min_length_scale));
  upper.head(d).setConstant(std::log(o.max_length_scale));
  lower(d) = std::log(o.min_signal_variance);
  upper(d) = std::log(o.max_signal_variance);
  lower(d + 1) = std::log(o.min_noise_variance);
  upper(d + 1) = std::log(o.max_noise_variance);
}

// Best point over every likelihood evaluation of every start, so an NLopt
// exception (roundoff, line-search failure) never loses progress.
struct FitSearch {
  MarginalLikelihood* likelihood = nullptr;
  Eigen::VectorXd best_theta;
  double best_value = -std::numeric_limits<double>::infinity();
  Eigen::VectorXd theta, gradient;
};

double NloptLikelihood(const std::vector<double>& x, std::vector<double>& grad, void* data) {
  auto* search = static_cast<FitSearch*>(data);
  search->theta = Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
  const double value = search->likelihood->Evaluate(
      search->theta, grad.empty() ? nullptr : &search->gradient, kMaxFitJitter);
  if (!grad.empty()) {
    Eigen::Map<Eigen::VectorXd>(grad.data(), static_cast<Eigen::Index>(grad.size())) =
        search->gradient;
  }
  if (value > search->best_value) {
    search->best_value = value;
    search->best_theta = search->theta;
  }
  return value;
}

void MaximiseFromStart(const Eigen::VectorXd& start, const Eigen::VectorXd& lower,
                       const Eigen::VectorXd& upper, int max_evaluations, FitSearch& search) {
  const auto p = static_cast<unsigned>(start.size());
  nlopt::opt opt(nlopt::LD_LBFGS, p);
  opt.set_lower_bounds(std::vector<double>(lower.data(), lower.data() + p));
  opt.set_upper_bounds(std::vector<double>(upper.data(), upper.data() + p));
  opt.set_max_objective(NloptLikelihood, &search);
  opt.set_maxeval(max_evaluations);
  // Hyperparameters only shape the surrogate: 1e-4 nats of likelihood or a
  // 0.1 % change of a hyperparameter (1e-3 in log space) does not move EI.
  opt.set_ftol_abs(1e-4);
  opt.set_xtol_abs(1e-3);
  std::vector<double> x(start.data(), start.data() + p);
  double value = 0.0;
  try {
    opt.optimize(x, value);
  } catch (const std::exception&) {
    // The best point seen is kept in `search`.
  }
}

Eigen::VectorXd RandomLogUniform(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                                 std::mt19937_64& rng) {
  Eigen::VectorXd theta(lower.size());
  for (Eigen::Index k = 0; k < lower.size(); ++k) {
    theta(k) = lower(k) + (upper(k) - lower(k)) * UniformUnit(rng);
  }
  return theta;
}

}  // namespace

double Matern52(double r) {
  return (1.0 + kSqrt5 * r + (5.0 / 3.0) * r * r) * std::exp(-kSqrt5 * r);
}

double GpLogMarginalLikelihood(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                               const KernelInputs& inputs, const Eigen::VectorXd& log_params,
                               Eigen::VectorXd* gradient) {
  const int d = inputs.dimension();
  CheckData(X, y, d);
  if (log_params.size() != d + 2) {
    throw InputError("GpLogMarginalLikelihood: log_params must have d + 2 = " +
                     std::to_string(d + 2) + " entries");
  }
  MarginalLikelihood likelihood(X, y, inputs);
  return likelihood.Evaluate(log_params, gradient, kMaxFitJitter);
}

GaussianProcess::GaussianProcess(KernelInputs inputs) : inputs_(std::move(inputs)) {
  hyper_.length_scales = Eigen::VectorXd::Constant(dimension(), 0.3);
}

void GaussianProcess::Condition(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                                const GpHyperparameters& h) {
  CheckData(X, y, dimension());
  if (h.length_scales.size() != dimension() || !(h.length_scales.array() > 0).all() ||
      !(h.signal_variance > 0) || !(h.noise_variance > 0)) {
    throw InputError("GaussianProcess: hyperparameters need " + std::to_string(dimension()) +
                     " positive length scales and positive signal and noise variances");
  }
  const Standardisation s = Standardise(y);
  y_mean_ = s.mean;
  y_scale_ = s.scale;
  const Eigen::VectorXd y_std = (y.array() - s.mean) / s.scale;

  MarginalLikelihood likelihood(X, y_std, inputs_);
  log_marginal_likelihood_ = likelihood.Evaluate(Pack(h), nullptr, kMaxConditionJitter);
  hyper_ = h;
  X_ = X;
  scaled_features_ = ScaledFeatures(X, inputs_, h.length_scales);
  if (likelihood.factorised()) {
    chol_lower_ = likelihood.cholesky_lower().triangularView<Eigen::Lower>();
    alpha_ = likelihood.alpha();
  } else {
    // Only reachable with a kernel matrix that no jitter up to the signal
    // variance repairs; a diagonal covariance keeps predictions finite.
    chol_lower_ = Eigen::MatrixXd::Identity(X.rows(), X.rows()) *
                  std::sqrt(h.signal_variance + h.noise_variance);
    alpha_ = y_std / (h.signal_variance + h.noise_variance);
  }
}

void GaussianProcess::Fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                          const GpFitOptions& options, std::mt19937_64& rng,
                          const GpHyperparameters* warm_start) {
  CheckData(X, y, dimension());
  CheckFitOptions(options);
  const int d = dimension();
  const Standardisation s = Standardise(y);
  const Eigen::VectorXd y_std = (y.array() - s.mean) / s.scale;

  Eigen::VectorXd lower, upper;
  LogBounds(options, d, lower, upper);
  GpHyperparameters initial;
  initial.length_scales = Eigen::VectorXd::Constant(d, 0.3);
  initial.signal_variance = 1.0;
  initial.noise_variance = 1e-4;
  if (warm_start != nullptr) {
    if (warm_start->length_scales.size() != d) {
      throw InputError("GaussianProcess::Fit: warm start has " +
                       std::to_string(warm_start->length_scales.size()) +
                       " length scales, expected " + std::to_string(d));
    }
    initial = *warm_start;
  }
  Eigen::VectorXd first = Pack(initial);
  // log of a non-positive warm start is NaN; the default point replaces it.
  for (Eigen::Index k = 0; k < first.size(); ++k) {
    if (!std::isfinite(first(k))) first(k) = 0.5 * (lower(k) + upper(k));
  }
  first = first.cwiseMax(lower).cwiseMin(upper);

  MarginalLikelihood likelihood(X, y_std, inputs_);
  FitSearch search;
  search.likelihood = &likelihood;
  search.best_theta = first;
  MaximiseFromStart(first, lower, upper, options.max_evaluations, search);
  for (int r = 0; r < options.restarts; ++r) {
    MaximiseFromStart(RandomLogUniform(lower, upper, rng), lower, upper, options.max_evaluations,
                      search);
  }
  GpHyperparameters best = UnpackHyperparameters(search.best_theta.cwiseMax(lower).cwiseMin(upper));
  for (int k = 0; k < d; ++k) {
    if (inputs_.TiedLengthScale(k)) best.length_scales(k) = best.length_scales(k - 1);
  }
  Condition(X, y, best);
}

GpPrediction GaussianProcess::Predict(const Eigen::VectorXd& x) const {
  Eigen::VectorXd mean, std;
  PredictBatch(x.transpose(), mean, std);
  return {mean(0), std(0)};
}

void GaussianProcess::PredictBatch(const Eigen::MatrixXd& Xs, Eigen::VectorXd& mean,
                                   Eigen::VectorXd& std) const {
  if (Xs.cols() != dimension()) {
    throw InputError("GaussianProcess: prediction points have " + std::to_string(Xs.cols()) +
                     " columns, expected " + std::to_string(dimension()));
  }
  const Eigen::MatrixXd Q = ScaledFeatures(Xs, inputs_, hyper_.length_scales);
  const Eigen::Index n = scaled_features_.cols();
  const Eigen::Index m = Xs.rows();
  // Cross-covariance k(x_i, x*_j), n x m.
  Eigen::MatrixXd Ks(n, m);
  for (Eigen::Index j = 0; j < m; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const double r = (scaled_features_.col(i) - Q.col(j)).norm();
      Ks(i, j) = hyper_.signal_variance * Matern52(r);
    }
  }
  mean.resize(m);
  std.resize(m);
  if (n == 0) {
    mean.setConstant(y_mean_);
    std.setConstant(std::sqrt(hyper_.signal_variance) * y_scale_);
    return;
  }
  mean = ((Ks.transpose() * alpha_).array() * y_scale_ + y_mean_).matrix();
  // var = k** - |L^-1 k*|^2; rounding can push it slightly below zero.
  chol_lower_.triangularView<Eigen::Lower>().solveInPlace(Ks);
  const Eigen::ArrayXd var =
      hyper_.signal_variance - Ks.colwise().squaredNorm().transpose().array();
  std = (var.max(0.0).sqrt() * y_scale_).matrix();
}

}  // namespace boicp
