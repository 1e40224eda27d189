#include "boicp/bo/gaussian_process.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "boicp/bo/sampling.hpp"

namespace boicp {
namespace {

GpHyperparameters MakeHyper(const Eigen::VectorXd& length_scales, double signal, double noise) {
  GpHyperparameters h;
  h.length_scales = length_scales;
  h.signal_variance = signal;
  h.noise_variance = noise;
  return h;
}

TEST(MaternTest, CorrelationAtZeroIsOne) { EXPECT_DOUBLE_EQ(Matern52(0.0), 1.0); }

TEST(MaternTest, ValueAtOneMatchesHandComputation) {
  // (1 + sqrt5 + 5/3) exp(-sqrt5) = 4.902734644236... * 0.106877925... = 0.523994108831...
  EXPECT_NEAR(Matern52(1.0), 0.5239941088318203, 1e-13);
  EXPECT_LT(Matern52(2.0), Matern52(1.0));
}

TEST(GaussianProcessTest, InterpolatesNoiselessData) {
  std::mt19937_64 rng(7);
  const Eigen::MatrixXd X = 0.5 * LatinHypercube(10, 2, rng);  // data only in [0, 0.5]^2
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    y(i) = std::sin(6.0 * X(i, 0)) + 3.0 * X(i, 1) * X(i, 1);
  }
  GaussianProcess gp({false, false});
  gp.Condition(X, y, MakeHyper(Eigen::Vector2d(0.3, 0.3), 1.0, 1e-8));

  double max_train_std = 0.0;
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const GpPrediction p = gp.Predict(X.row(i).transpose());
    EXPECT_NEAR(p.mean, y(i), 1e-5) << "training point " << i;
    EXPECT_GE(p.std, 0.0);
    max_train_std = std::max(max_train_std, p.std);
  }
  EXPECT_LT(max_train_std, 1e-3 * gp.output_scale());

  // Posterior std grows with distance from the data, towards the prior std.
  const double near = gp.Predict(Eigen::Vector2d(0.55, 0.55)).std;
  const double far = gp.Predict(Eigen::Vector2d(1.0, 1.0)).std;
  EXPECT_GT(near, 10.0 * max_train_std);
  EXPECT_GT(far, near);
  EXPECT_GT(far, 0.5 * gp.output_scale());
}

TEST(GaussianProcessTest, TwoPointPosteriorMatchesHandComputation) {
  // x = {0.2, 0.6}, y = {1, 3}: standardised with mean 2 and population std 1,
  // so z = {-1, 1} and caller units equal standardised units up to the shift.
  // l = 0.4, signal 1, noise 0.01; query x* = 0.3.
  const double s5 = std::sqrt(5.0);
  auto matern = [s5](double r) { return (1.0 + s5 * r + 5.0 * r * r / 3.0) * std::exp(-s5 * r); };
  const double m = matern(0.4 / 0.4);  // k(x1, x2)
  const double a = matern(0.1 / 0.4);  // k(x*, x1)
  const double b = matern(0.3 / 0.4);  // k(x*, x2)
  const double diag = 1.0 + 0.01;
  const double det = diag * diag - m * m;
  // K^-1 z = (-1, 1) / (diag - m) by symmetry of K, so k*^T K^-1 z = (b - a) / (diag - m).
  const double expected_mean = 2.0 + (b - a) / (diag - m);
  // k*^T K^-1 k* with K^-1 = [[diag, -m], [-m, diag]] / det.
  const double expected_var = 1.0 - (diag * (a * a + b * b) - 2.0 * m * a * b) / det;
  // Same numbers evaluated once by hand (Python) as a guard against slips above.
  EXPECT_NEAR(expected_mean, 1.433521019676893, 1e-12);
  EXPECT_NEAR(expected_var, 0.0596143329893698, 1e-12);

  Eigen::MatrixXd X(2, 1);
  X << 0.2, 0.6;
  GaussianProcess gp({false});
  gp.Condition(X, Eigen::Vector2d(1.0, 3.0),
               MakeHyper(Eigen::VectorXd::Constant(1, 0.4), 1.0, 0.01));
  const GpPrediction p = gp.Predict(Eigen::VectorXd::Constant(1, 0.3));
  EXPECT_NEAR(p.mean, expected_mean, 1e-10);
  EXPECT_NEAR(p.std, std::sqrt(expected_var), 1e-10);
}

TEST(GaussianProcessTest, PeriodicDimensionJoinsItsEnds) {
  std::mt19937_64 rng(3);
  const Eigen::MatrixXd X = LatinHypercube(12, 2, rng);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) y(i) = std::cos(9.0 * X(i, 0)) + X(i, 1);
  const GpHyperparameters h = MakeHyper(Eigen::Vector2d(0.2, 0.4), 1.0, 1e-4);

  GaussianProcess periodic({true, false});
  periodic.Condition(X, y, h);
  GaussianProcess plain({false, false});
  plain.Condition(X, y, h);
  for (double v : {0.1, 0.5, 0.9}) {
    const GpPrediction at0 = periodic.Predict(Eigen::Vector2d(0.0, v));
    const GpPrediction at1 = periodic.Predict(Eigen::Vector2d(1.0, v));
    EXPECT_NEAR(at0.mean, at1.mean, 1e-12);
    EXPECT_NEAR(at0.std, at1.std, 1e-12);
    // Without the embedding the two ends are different points.
    EXPECT_GT(std::abs(plain.Predict(Eigen::Vector2d(0.0, v)).mean -
                       plain.Predict(Eigen::Vector2d(1.0, v)).mean),
              1e-3);
  }
}

// The analytic gradient against central differences at theta.
void ExpectGradientMatchesFiniteDifferences(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                                            const KernelInputs& inputs,
                                            const Eigen::VectorXd& theta) {
  Eigen::VectorXd gradient;
  GpLogMarginalLikelihood(X, y, inputs, theta, &gradient);
  ASSERT_EQ(gradient.size(), theta.size());
  for (Eigen::Index k = 0; k < theta.size(); ++k) {
    const double h = 1e-6;
    Eigen::VectorXd plus = theta, minus = theta;
    plus(k) += h;
    minus(k) -= h;
    const double numeric = (GpLogMarginalLikelihood(X, y, inputs, plus, nullptr) -
                            GpLogMarginalLikelihood(X, y, inputs, minus, nullptr)) /
                           (2.0 * h);
    EXPECT_NEAR(gradient(k), numeric, 1e-5 * std::max(1.0, std::abs(numeric)))
        << "parameter " << k << " at theta " << theta.transpose();
  }
}

TEST(GaussianProcessTest, LikelihoodGradientMatchesFiniteDifferences) {
  std::mt19937_64 rng(11);
  const std::vector<bool> periodic = {false, true, false};
  const Eigen::MatrixXd X = UniformPoints(15, 3, rng);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    y(i) = std::sin(4.0 * X(i, 0)) * std::cos(2.0 * X(i, 1)) + X(i, 2) + 0.1 * UniformUnit(rng);
  }
  const std::vector<Eigen::VectorXd> thetas = {
      (Eigen::VectorXd(5) << std::log(0.3), std::log(0.3), std::log(0.3), 0.0, std::log(1e-3))
          .finished(),
      (Eigen::VectorXd(5) << std::log(0.05), std::log(1.5), std::log(0.2), std::log(3.0),
       std::log(0.05))
          .finished(),
      (Eigen::VectorXd(5) << std::log(2.0), std::log(0.1), std::log(0.7), std::log(0.2),
       std::log(1e-5))
          .finished()};
  for (const Eigen::VectorXd& theta : thetas) {
    ExpectGradientMatchesFiniteDifferences(X, y, periodic, theta);
  }
}

// A rotation's second and third length scales are tied to its first, so
// their derivatives are zero.
TEST(GaussianProcessTest, RotationLikelihoodGradientMatchesFiniteDifferences) {
  std::mt19937_64 rng(11);
  const KernelInputs inputs(
      {InputKind::kRotation, InputKind::kRotation, InputKind::kRotation, InputKind::kLinear});
  const Eigen::MatrixXd X = UniformPoints(15, 4, rng);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const Eigen::Matrix3d R = RotationFromUnit(X.row(i).head<3>().transpose());
    y(i) = R(0, 0) + 0.5 * R(2, 1) + X(i, 3) + 0.1 * UniformUnit(rng);
  }
  const Eigen::VectorXd theta = (Eigen::VectorXd(6) << std::log(0.2), std::log(0.7), std::log(3.0),
                                 std::log(0.4), std::log(1.5), std::log(1e-3))
                                    .finished();
  ExpectGradientMatchesFiniteDifferences(X, y, inputs, theta);
  Eigen::VectorXd gradient;
  GpLogMarginalLikelihood(X, y, inputs, theta, &gradient);
  EXPECT_EQ(gradient(1), 0.0);
  EXPECT_EQ(gradient(2), 0.0);
}

TEST(GaussianProcessTest, PredictBatchMatchesPredict) {
  std::mt19937_64 rng(5);
  const Eigen::MatrixXd X = UniformPoints(20, 3, rng);
  const Eigen::VectorXd y = X.rowwise().squaredNorm();
  GaussianProcess gp({false, true, false});
  gp.Condition(X, y, MakeHyper(Eigen::Vector3d(0.2, 0.5, 0.3), 2.0, 1e-3));
  const Eigen::MatrixXd Xs = UniformPoints(50, 3, rng);
  Eigen::VectorXd mean, std;
  gp.PredictBatch(Xs, mean, std);
  ASSERT_EQ(mean.size(), 50);
  for (Eigen::Index i = 0; i < Xs.rows(); ++i) {
    const GpPrediction p = gp.Predict(Xs.row(i).transpose());
    EXPECT_NEAR(mean(i), p.mean, 1e-12);
    EXPECT_NEAR(std(i), p.std, 1e-12);
  }
}

TEST(GaussianProcessTest, FitFindsWhichDimensionMatters) {
  // y varies quickly along x0 and not at all along x1: ARD should give x1 a
  // much longer length scale.
  std::mt19937_64 rng(21);
  const Eigen::MatrixXd X = LatinHypercube(40, 2, rng);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) y(i) = std::sin(8.0 * X(i, 0));
  GaussianProcess gp({false, false});
  gp.Fit(X, y, GpFitOptions{}, rng);
  const GpHyperparameters& h = gp.hyperparameters();
  std::printf("fitted l = (%.3f, %.3f), signal %.3g, noise %.3g\n", h.length_scales(0),
              h.length_scales(1), h.signal_variance, h.noise_variance);
  EXPECT_LT(h.length_scales(0), 0.5);
  EXPECT_GT(h.length_scales(1), 3.0 * h.length_scales(0));
}

TEST(GaussianProcessTest, FitAtNinetyPointsBeatsDefaultHyperparameters) {
  std::mt19937_64 rng(42);
  const std::vector<bool> periodic = {false, false, true};
  const Eigen::MatrixXd X = UniformPoints(90, 3, rng);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    y(i) = std::sin(5.0 * X(i, 0)) + (X(i, 1) - 0.3) * (X(i, 1) - 0.3) +
           0.5 * std::cos(6.283185307179586 * X(i, 2)) + 0.01 * UniformUnit(rng);
  }
  GaussianProcess reference({false, false, true});
  reference.Condition(X, y, MakeHyper(Eigen::Vector3d::Constant(0.3), 1.0, 1e-4));

  GaussianProcess gp(periodic);
  const int repeats = 20;
  const auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < repeats; ++r) gp.Fit(X, y, GpFitOptions{}, rng);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() /
      repeats;
  std::printf("GaussianProcess::Fit (n = 90, d = 3, default GpFitOptions): %.2f ms per fit\n", ms);
  EXPECT_GE(gp.LogMarginalLikelihood(), reference.LogMarginalLikelihood());
  EXPECT_TRUE(std::isfinite(gp.LogMarginalLikelihood()));
}

TEST(GaussianProcessTest, SurvivesDuplicatePointsAndConstantOutputs) {
  Eigen::MatrixXd X = Eigen::MatrixXd::Constant(6, 2, 0.5);
  const Eigen::VectorXd y = Eigen::VectorXd::Constant(6, 4.0);
  GaussianProcess gp({false, false});
  gp.Condition(X, y, MakeHyper(Eigen::Vector2d(0.3, 0.3), 1.0, 1e-12));
  GpPrediction p = gp.Predict(Eigen::Vector2d(0.5, 0.5));
  EXPECT_NEAR(p.mean, 4.0, 1e-6);
  EXPECT_TRUE(std::isfinite(p.std));

  std::mt19937_64 rng(1);
  gp.Fit(X, y, GpFitOptions{}, rng);
  p = gp.Predict(Eigen::Vector2d(0.1, 0.9));
  EXPECT_TRUE(std::isfinite(p.mean));
  EXPECT_TRUE(std::isfinite(p.std));
  EXPECT_TRUE(std::isfinite(gp.LogMarginalLikelihood()));
}

}  // namespace
}  // namespace boicp
