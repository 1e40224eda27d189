#include "boicp/bo/acquisition.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "boicp/bo/sampling.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

// Standard normal values used below (Phi = CDF, phi = density):
// phi(0) = 0.3989422804014327, Phi(1) = 0.8413447460685429, phi(1) = 0.24197072451914337,
// Phi(-0.5) = 0.3085375387259869, phi(0.5) = 0.3520653267642995.

TEST(ExpectedImprovementTest, MatchesClosedFormAtHandPickedPoints) {
  // mean == best, xi = 0: z = 0, EI = std * phi(0).
  EXPECT_NEAR(ExpectedImprovement(2.0, 1.0, 2.0, 0.0), 0.3989422804014327, 1e-14);
  // best - mean = 1, std 1: EI = 1 * Phi(1) + 1 * phi(1).
  EXPECT_NEAR(ExpectedImprovement(0.0, 1.0, 1.0, 0.0), 0.8413447460685429 + 0.24197072451914337,
              1e-14);
  // best - mean - xi = -1, std 2: z = -0.5, EI = -1 * Phi(-0.5) + 2 * phi(-0.5).
  EXPECT_NEAR(ExpectedImprovement(0.0, 2.0, 0.0, 1.0),
              -0.3085375387259869 + 2.0 * 0.3520653267642995, 1e-14);
  // std == 0: the improvement itself, or zero.
  EXPECT_DOUBLE_EQ(ExpectedImprovement(0.0, 0.0, 1.0, 0.25), 0.75);
  EXPECT_DOUBLE_EQ(ExpectedImprovement(2.0, 0.0, 1.0, 0.0), 0.0);
}

TEST(ExpectedImprovementTest, IsNonNegativeAndMonotone) {
  double previous = -1.0;
  for (double mean = 10.0; mean >= -10.0; mean -= 0.25) {
    for (double std : {0.0, 1e-12, 1e-3, 0.1, 1.0, 10.0}) {
      const double ei = ExpectedImprovement(mean, std, 0.0, 0.01);
      EXPECT_GE(ei, 0.0) << "mean " << mean << " std " << std;
      EXPECT_TRUE(std::isfinite(ei));
    }
    // A lower predicted mean never reduces EI.
    const double ei = ExpectedImprovement(mean, 0.5, 0.0, 0.01);
    EXPECT_GE(ei, previous);
    previous = ei;
  }
}

TEST(ExpectedImprovementTest, ProbabilityOfImprovementClosedForm) {
  EXPECT_NEAR(ProbabilityOfImprovement(0.0, 1.0, 1.0, 0.0), 0.8413447460685429, 1e-14);
  EXPECT_NEAR(ProbabilityOfImprovement(0.0, 2.0, 0.0, 1.0), 0.3085375387259869, 1e-14);
  EXPECT_DOUBLE_EQ(ProbabilityOfImprovement(0.0, 0.0, 1.0, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(ProbabilityOfImprovement(1.0, 0.0, 1.0, 0.0), 0.0);
}

GaussianProcess QuadraticOnLine() {
  // y = (x - 0.6)^2 on five evenly spaced points: the minimum lies between
  // the samples at 0.5 and 0.75.
  Eigen::MatrixXd X(5, 1);
  X << 0.0, 0.25, 0.5, 0.75, 1.0;
  const Eigen::VectorXd y = (X.col(0).array() - 0.6).square().matrix();
  GaussianProcess gp({false});
  GpHyperparameters h;
  h.length_scales = Eigen::VectorXd::Constant(1, 0.3);
  h.signal_variance = 1.0;
  h.noise_variance = 1e-6;
  gp.Condition(X, y, h);
  return gp;
}

TEST(AcquisitionTest, MaximiserPicksTheExpectedRegionIn1D) {
  const GaussianProcess gp = QuadraticOnLine();
  const double best = std::pow(0.5 - 0.6, 2);
  std::mt19937_64 rng(9);
  AcquisitionOptions options;
  const Eigen::VectorXd x = MaximiseExpectedImprovement(gp, best, options, rng);
  ASSERT_EQ(x.size(), 1);
  EXPECT_GT(x(0), 0.5);
  EXPECT_LT(x(0), 0.75);

  // The result is at least as good as a fine grid search.
  const double xi = options.xi * gp.output_scale();
  double grid_best = 0.0;
  for (int i = 0; i <= 10000; ++i) {
    const GpPrediction p = gp.Predict(Eigen::VectorXd::Constant(1, i / 10000.0));
    grid_best = std::max(grid_best, ExpectedImprovement(p.mean, p.std, best, xi));
  }
  const GpPrediction at = gp.Predict(x);
  EXPECT_GE(ExpectedImprovement(at.mean, at.std, best, xi), grid_best * (1.0 - 1e-6));
}

TEST(AcquisitionTest, MaximiserStaysInsideTheBox) {
  // A minimum pressed against the corner (1, 1, 0) drives EI to the boundary.
  std::mt19937_64 rng(4);
  const Eigen::MatrixXd X = LatinHypercube(15, 3, rng);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) y(i) = -X(i, 0) - X(i, 1) + X(i, 2);
  GaussianProcess gp({false, false, false});
  gp.Fit(X, y, GpFitOptions{}, rng);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd x = MaximiseExpectedImprovement(gp, y.minCoeff(), {}, rng);
    ASSERT_EQ(x.size(), 3);
    EXPECT_TRUE((x.array() >= 0.0).all() && (x.array() <= 1.0).all()) << x.transpose();
  }
}

TEST(AcquisitionTest, ThreadCountDoesNotChangeTheMaximiser) {
  std::mt19937_64 data_rng(6);
  const Eigen::MatrixXd X = LatinHypercube(20, 3, data_rng);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) y(i) = std::sin(6.0 * X(i, 0)) + X(i, 1) * X(i, 2);
  GaussianProcess gp({false, true, false});
  gp.Fit(X, y, GpFitOptions{}, data_rng);
  AcquisitionOptions options;
  options.random_candidates = 1111;  // not a multiple of the scoring block
  for (int threads : {2, 3}) {
    std::mt19937_64 serial_rng(21), parallel_rng(21);
    const Eigen::VectorXd serial =
        MaximiseExpectedImprovement(gp, y.minCoeff(), options, serial_rng);
    const Eigen::VectorXd parallel =
        MaximiseExpectedImprovement(gp, y.minCoeff(), options, parallel_rng, threads);
    EXPECT_TRUE(serial == parallel) << serial.transpose() << " vs " << parallel.transpose();
  }
}

TEST(AcquisitionTest, MaxProbabilityOfImprovementIsAProbability) {
  const GaussianProcess gp = QuadraticOnLine();
  std::mt19937_64 rng(2);
  const double incumbent = std::pow(0.5 - 0.6, 2);
  const double p = MaxProbabilityOfImprovement(gp, incumbent, 0.01, 500, rng);
  EXPECT_GT(p, 0.0);
  EXPECT_LE(p, 1.0);
  // Nothing plausibly beats a far lower incumbent; everything beats a far higher one.
  EXPECT_LT(MaxProbabilityOfImprovement(gp, -100.0, 0.01, 500, rng), 1e-6);
  EXPECT_GT(MaxProbabilityOfImprovement(gp, 100.0, 0.01, 500, rng), 1.0 - 1e-6);
  EXPECT_THROW(MaxProbabilityOfImprovement(gp, incumbent, 0.01, 0, rng), InputError);
}

}  // namespace
}  // namespace boicp
