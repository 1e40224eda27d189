#include "boicp/bo/bayes_opt.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "boicp/bo/sampling.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Branin-Hoo on x1 in [-5, 10], x2 in [0, 15], mapped from the unit square.
// Three global minima, all 0.397887.
double BraninUnit(const Eigen::VectorXd& u) {
  const double x1 = 15.0 * u(0) - 5.0;
  const double x2 = 15.0 * u(1);
  const double b = 5.1 / (4.0 * kPi * kPi);
  const double c = 5.0 / kPi;
  const double t = 1.0 / (8.0 * kPi);
  const double q = x2 - b * x1 * x1 + c * x1 - 6.0;
  return q * q + 10.0 * (1.0 - t) * std::cos(x1) + 10.0;
}
constexpr double kBraninMinimum = 0.397887;

// Hartmann 3-D on [0,1]^3; global minimum -3.86278 at (0.114614, 0.555649, 0.852547).
double Hartmann3(const Eigen::VectorXd& x) {
  static const double kAlpha[4] = {1.0, 1.2, 3.0, 3.2};
  static const double kA[4][3] = {{3, 10, 30}, {0.1, 10, 35}, {3, 10, 30}, {0.1, 10, 35}};
  static const double kP[4][3] = {{0.3689, 0.1170, 0.2673},
                                  {0.4699, 0.4387, 0.7470},
                                  {0.1091, 0.8732, 0.5547},
                                  {0.0381, 0.5743, 0.8828}};
  double f = 0.0;
  for (int i = 0; i < 4; ++i) {
    double s = 0.0;
    for (int j = 0; j < 3; ++j) s += kA[i][j] * (x(j) - kP[i][j]) * (x(j) - kP[i][j]);
    f -= kAlpha[i] * std::exp(-s);
  }
  return f;
}
constexpr double kHartmann3Minimum = -3.86278;

BayesOptOptions SearchBudget(int initial, int iterations) {
  BayesOptOptions o;
  o.initial_samples = initial;
  o.iterations = iterations;
  return o;
}

// Runs seeds 1..10 and counts how often best_y ends within `tolerance` of the
// known minimum; every seed's result is printed.
int CountSuccesses(const char* name, const UnitObjective& f, int d, double minimum,
                   double tolerance, const BayesOptOptions& options) {
  int successes = 0;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const BayesOptResult r =
        MinimiseBayesOpt(f, std::vector<bool>(static_cast<size_t>(d), false), options, seed);
    const bool ok = r.best_y - minimum <= tolerance;
    successes += ok ? 1 : 0;
    std::printf("%s seed %2llu: best %.6f (gap %.2e) at evaluation %zu, P(better) %.3f %s\n", name,
                static_cast<unsigned long long>(seed), r.best_y, r.best_y - minimum, r.best_index,
                r.probability_better, ok ? "" : "MISS");
  }
  return successes;
}

TEST(LatinHypercubeTest, OnePointPerSlicePerAxis) {
  std::mt19937_64 rng(17);
  const int n = 17, d = 4;
  const Eigen::MatrixXd X = LatinHypercube(n, d, rng);
  ASSERT_EQ(X.rows(), n);
  ASSERT_EQ(X.cols(), d);
  for (int k = 0; k < d; ++k) {
    std::set<int> slices;
    for (int i = 0; i < n; ++i) {
      ASSERT_GE(X(i, k), 0.0);
      ASSERT_LT(X(i, k), 1.0);
      slices.insert(static_cast<int>(std::floor(X(i, k) * n)));
    }
    EXPECT_EQ(static_cast<int>(slices.size()), n) << "axis " << k;
  }
}

TEST(LatinHypercubeTest, SameSeedSameDesign) {
  std::mt19937_64 a(5), b(5), c(6);
  const Eigen::MatrixXd A = LatinHypercube(12, 3, a);
  const Eigen::MatrixXd B = LatinHypercube(12, 3, b);
  const Eigen::MatrixXd C = LatinHypercube(12, 3, c);
  EXPECT_TRUE(A == B);
  EXPECT_FALSE(A == C);
}

TEST(BayesOptTest, FindsBraninMinimum) {
  // Budget: 10 Latin-hypercube samples + 30 EI steps; success = within 0.05.
  // Branin's outputs span 0.4 .. 300 (std ~ 50), so the default margin of 0.01
  // output std (~0.5) is ten times the tolerance and EI would stop refining
  // short of it; a margin of 0.001 std (~0.05) matches the tolerance.
  BayesOptOptions options = SearchBudget(10, 30);
  options.acquisition.xi = 0.001;
  const int successes = CountSuccesses("Branin", BraninUnit, 2, kBraninMinimum, 0.05, options);
  EXPECT_GE(successes, 9);
}

TEST(BayesOptTest, FindsHartmann3Minimum) {
  // Budget: 10 Latin-hypercube samples + 40 EI steps, default options;
  // success = within 0.1.
  const int successes =
      CountSuccesses("Hartmann3", Hartmann3, 3, kHartmann3Minimum, 0.1, SearchBudget(10, 40));
  EXPECT_GE(successes, 9);
}

TEST(BayesOptTest, SameSeedGivesIdenticalHistory) {
  BayesOptOptions options = SearchBudget(5, 8);
  options.refit_every = 3;
  const std::vector<bool> periodic = {false, true};
  const BayesOptResult a = MinimiseBayesOpt(BraninUnit, periodic, options, 77);
  const BayesOptResult b = MinimiseBayesOpt(BraninUnit, periodic, options, 77);
  const BayesOptResult c = MinimiseBayesOpt(BraninUnit, periodic, options, 78);
  ASSERT_EQ(a.history.size(), 13u);
  ASSERT_EQ(a.history.size(), b.history.size());
  for (size_t i = 0; i < a.history.size(); ++i) {
    EXPECT_TRUE(a.history[i].x == b.history[i].x) << "evaluation " << i;
    EXPECT_EQ(a.history[i].y, b.history[i].y) << "evaluation " << i;
  }
  EXPECT_EQ(a.best_y, b.best_y);
  EXPECT_EQ(a.gp_mean_at_best, b.gp_mean_at_best);
  EXPECT_EQ(a.probability_better, b.probability_better);
  EXPECT_FALSE(a.history.back().x == c.history.back().x);
}

// Batch-parallel BO: q proposals per round, evaluated on `threads` threads.
// The answer depends on q only; threads = 1 is the serial twin.
class BayesOptBatches : public ::testing::TestWithParam<int> {};

TEST_P(BayesOptBatches, ParallelRoundsEqualTheirSerialTwin) {
  BayesOptOptions options = SearchBudget(5, 9);
  options.batch_size = GetParam();
  const BayesOptResult serial = MinimiseBayesOpt(BraninUnit, {false, false}, options, 11);
  options.threads = 2;
  const BayesOptResult parallel = MinimiseBayesOpt(BraninUnit, {false, false}, options, 11);
  ASSERT_EQ(serial.history.size(), 14u);
  ASSERT_EQ(parallel.history.size(), serial.history.size());
  for (size_t i = 0; i < serial.history.size(); ++i) {
    EXPECT_TRUE(serial.history[i].x == parallel.history[i].x) << "evaluation " << i;
    EXPECT_EQ(serial.history[i].y, parallel.history[i].y) << "evaluation " << i;
  }
  EXPECT_EQ(serial.probability_better, parallel.probability_better);
}

TEST_P(BayesOptBatches, ProposalsOfARoundAreDistinctAndToldThePreviousRoundsBest) {
  const int q = GetParam();
  BayesOptOptions options = SearchBudget(4, 8);
  options.batch_size = q;
  std::vector<double> incumbents;
  std::vector<double> values;
  const BoundedObjective f = [&](const Eigen::VectorXd& x, double incumbent) {
    incumbents.push_back(incumbent);
    values.push_back(BraninUnit(x));
    return values.back();
  };
  const BayesOptResult result = MinimiseBayesOpt(f, {false, false}, options, 3);
  ASSERT_EQ(values.size(), 12u);
  for (size_t i = 0; i < values.size(); ++i) {
    const size_t round_start = i < 4 ? i - i % q : 4 + (i - 4) - (i - 4) % q;
    double before = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < round_start; ++k) before = std::min(before, values[k]);
    EXPECT_EQ(incumbents[i], before) << "evaluation " << i;
    if (i > round_start) {
      EXPECT_FALSE(result.history[i].x.isApprox(result.history[i - 1].x, 1e-6))
          << "evaluation " << i << " repeats its round's previous proposal";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(BatchSizes, BayesOptBatches, ::testing::Values(1, 2, 3));

TEST(BayesOptTest, ReportsProgressAndKeepsInitialPointsFirst) {
  const std::vector<Eigen::VectorXd> initial = {Eigen::Vector2d(0.25, 1.5),
                                                Eigen::Vector2d(0.5, 0.5)};
  std::vector<int> done_calls;
  double last_best = std::numeric_limits<double>::infinity();
  const BayesOptProgress progress = [&](int done, int total, double best_y) {
    done_calls.push_back(done);
    EXPECT_EQ(total, 9);
    EXPECT_LE(best_y, last_best);
    last_best = best_y;
  };
  const BayesOptResult r =
      MinimiseBayesOpt(BraninUnit, {false, false}, SearchBudget(4, 5), 3, initial, progress);
  ASSERT_EQ(r.history.size(), 9u);
  EXPECT_TRUE(r.history[0].x == Eigen::Vector2d(0.25, 1.0));  // clamped into the box
  EXPECT_TRUE(r.history[1].x == Eigen::Vector2d(0.5, 0.5));
  EXPECT_EQ(done_calls, (std::vector<int>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(r.best_y, r.history[r.best_index].y);
  for (const BayesOptSample& s : r.history) {
    EXPECT_GE(s.y, r.best_y);
    EXPECT_TRUE((s.x.array() >= 0.0).all() && (s.x.array() <= 1.0).all());
  }
  EXPECT_GE(r.probability_better, 0.0);
  EXPECT_LE(r.probability_better, 1.0);
  EXPECT_GE(r.gp_std_at_best, 0.0);
  EXPECT_EQ(r.hyperparameters.length_scales.size(), 2);
}

TEST(BayesOptTest, InitialPointsBeyondTheBudgetAreAllUsed) {
  const std::vector<Eigen::VectorXd> initial(3, Eigen::VectorXd::Constant(1, 0.3));
  const BayesOptResult r =
      MinimiseBayesOpt([](const Eigen::VectorXd& x) { return (x(0) - 0.7) * (x(0) - 0.7); }, {true},
                       SearchBudget(2, 1), 1, initial);
  EXPECT_EQ(r.history.size(), 4u);
}

TEST(BayesOptTest, StopRequestThrowsCancelledBeforeTheNextEvaluation) {
  int evaluations = 0;
  int polls = 0;
  const UnitObjective f = [&](const Eigen::VectorXd& x) {
    ++evaluations;
    return BraninUnit(x);
  };
  const std::function<bool()> stop = [&] { return ++polls > 7; };
  BayesOptOptions one_at_a_time = SearchBudget(5, 10);
  one_at_a_time.batch_size = 1;
  EXPECT_THROW(MinimiseBayesOpt(f, {false, false}, one_at_a_time, 1, {}, {}, stop), Cancelled);
  EXPECT_EQ(evaluations, 7);

  // In rounds of q = 2 the poll comes before each round: 5 design points take
  // 3 rounds, so 7 polls allow 3 + 4 rounds = 13 evaluations.
  evaluations = 0;
  polls = 0;
  EXPECT_THROW(MinimiseBayesOpt(f, {false, false}, SearchBudget(5, 10), 1, {}, {}, stop),
               Cancelled);
  EXPECT_EQ(evaluations, 13);
}

// A search ended early by `enough` and then resumed spends the whole budget
// once: the resumed run repeats none of the evaluations it was handed.
TEST(BayesOptTest, AnEarlyEndIsResumedToTheWholeBudgetWithoutRepeats) {
  const BayesOptOptions options = SearchBudget(6, 10);
  const std::vector<bool> periodic = {false, false};
  int calls = 0;
  const BoundedObjective f = [&](const Eigen::VectorXd& x, double) {
    ++calls;
    return BraninUnit(x);
  };
  BayesOptHooks hooks;
  hooks.enough = [](const std::vector<BayesOptSample>& history) { return history.size() >= 8; };
  const BayesOptResult early = MinimiseBayesOpt(f, periodic, options, 7, {}, hooks);
  EXPECT_EQ(early.history.size(), 8u);  // the design, then one round of two
  EXPECT_EQ(calls, 8);

  BayesOptHooks rest;
  rest.resume = early.history;
  const BayesOptResult whole = MinimiseBayesOpt(f, periodic, options, 7, {}, rest);
  ASSERT_EQ(whole.history.size(), 16u);
  EXPECT_EQ(calls, 16);
  for (size_t i = 0; i < early.history.size(); ++i) {
    EXPECT_TRUE(whole.history[i].x == early.history[i].x) << "evaluation " << i;
  }
  EXPECT_LE(whole.best_y, early.best_y);

  // `enough` is asked only once the initial design is complete.
  hooks.enough = [](const std::vector<BayesOptSample>&) { return true; };
  EXPECT_EQ(MinimiseBayesOpt(f, periodic, options, 7, {}, hooks).history.size(), 6u);
}

TEST(BayesOptTest, InvalidOptionsThrowInputError) {
  const UnitObjective f = [](const Eigen::VectorXd& x) { return x.squaredNorm(); };
  const std::vector<bool> two = {false, false};
  BayesOptOptions o = SearchBudget(0, 3);
  EXPECT_THROW(MinimiseBayesOpt(f, two, o, 1), InputError);
  o = SearchBudget(3, -1);
  EXPECT_THROW(MinimiseBayesOpt(f, two, o, 1), InputError);
  o = SearchBudget(3, 3);
  o.refit_every = 0;
  EXPECT_THROW(MinimiseBayesOpt(f, two, o, 1), InputError);
  o = SearchBudget(3, 3);
  o.batch_size = 0;
  EXPECT_THROW(MinimiseBayesOpt(f, two, o, 1), InputError);
  o = SearchBudget(3, 3);
  o.threads = 0;
  EXPECT_THROW(MinimiseBayesOpt(f, two, o, 1), InputError);
  EXPECT_THROW(MinimiseBayesOpt(f, {}, SearchBudget(3, 3), 1), InputError);
  EXPECT_THROW(MinimiseBayesOpt(f, two, SearchBudget(3, 3), 1, {Eigen::Vector3d(0.1, 0.2, 0.3)}),
               InputError);
  try {
    MinimiseBayesOpt(f, two, SearchBudget(0, 3), 1);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("initial_samples"), std::string::npos) << e.what();
  }
}

TEST(BayesOptTest, NonFiniteObjectiveNamesTheEvaluation) {
  int calls = 0;
  const UnitObjective f = [&](const Eigen::VectorXd&) {
    return ++calls == 4 ? std::numeric_limits<double>::quiet_NaN() : 1.0;
  };
  try {
    MinimiseBayesOpt(f, {false}, SearchBudget(5, 2), 1);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("evaluation 3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace boicp
