#include "boicp/bo/acquisition.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <numeric>
#include <string>
#include <vector>

#include <nlopt.hpp>

#include "boicp/bo/sampling.hpp"
#include "boicp/util/parallel_for.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;
constexpr Eigen::Index kScoringBlock = 250;  // candidates per block of GP predictions
constexpr double kInvSqrt2Pi = 0.39894228040143267794;

// erfc keeps full relative accuracy in the lower tail, where EI lives.
double NormalCdf(double z) { return 0.5 * std::erfc(-z * kInvSqrt2); }
double NormalPdf(double z) { return kInvSqrt2Pi * std::exp(-0.5 * z * z); }

// EI of the GP at x in the standardised output scale, where xi is applied.
struct StandardisedEi {
  const GaussianProcess* gp;
  double best;  // standardised
  double xi;

  double operator()(double mean, double std) const {
    const double s = gp->output_scale();
    return ExpectedImprovement((mean - gp->output_mean()) / s, std / s, best, xi);
  }
};

struct LocalSearch {
  StandardisedEi ei;
  Eigen::VectorXd x;
  Eigen::VectorXd best_x;
  double best_value = 0.0;
};

double NloptEi(const std::vector<double>& u, std::vector<double>& /*grad*/, void* data) {
  auto* search = static_cast<LocalSearch*>(data);
  for (Eigen::Index k = 0; k < search->x.size(); ++k) {
    search->x(k) = std::clamp(u[static_cast<size_t>(k)], 0.0, 1.0);
  }
  const GpPrediction p = search->ei.gp->Predict(search->x);
  const double value = search->ei(p.mean, p.std);
  if (value > search->best_value) {
    search->best_value = value;
    search->best_x = search->x;
  }
  return value;
}

// Derivative-free bounded refinement from one candidate; `search` keeps the
// best point seen even when NLopt gives up with an exception.
void RefineWithBobyqa(const Eigen::VectorXd& start, int max_evaluations, LocalSearch& search) {
  const auto d = static_cast<unsigned>(start.size());
  nlopt::opt opt(nlopt::LN_BOBYQA, d);
  opt.set_lower_bounds(0.0);
  opt.set_upper_bounds(1.0);
  opt.set_max_objective(NloptEi, &search);
  opt.set_maxeval(max_evaluations);
  opt.set_xtol_abs(1e-6);
  // Candidates are a few tenths apart in 6-D; the trust region shrinks from here.
  opt.set_initial_step(0.1);
  std::vector<double> u(start.data(), start.data() + d);
  double value = 0.0;
  try {
    opt.optimize(u, value);
  } catch (const std::exception&) {
    // Keep the best point seen.
  }
}

// Indices of the k largest scores, ties broken by index so results do not
// depend on the sort implementation.
std::vector<Eigen::Index> TopIndices(const Eigen::VectorXd& score, int k) {
  std::vector<Eigen::Index> order(static_cast<size_t>(score.size()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  const auto top = static_cast<ptrdiff_t>(std::min<size_t>(static_cast<size_t>(k), order.size()));
  std::partial_sort(order.begin(), order.begin() + top, order.end(),
                    [&](Eigen::Index a, Eigen::Index b) {
                      return score(a) > score(b) || (score(a) == score(b) && a < b);
                    });
  order.resize(static_cast<size_t>(top));
  return order;
}

void CheckAcquisitionOptions(const AcquisitionOptions& o) {
  if (o.random_candidates < 1 || o.local_starts < 0 || o.local_max_evaluations < 1 ||
      !std::isfinite(o.xi)) {
    throw InputError(
        "AcquisitionOptions: need random_candidates >= 1, local_starts >= 0, "
        "local_max_evaluations >= 1 and a finite xi");
  }
}

}  // namespace

double ExpectedImprovement(double mean, double std, double best, double xi) {
  const double improvement = best - mean - xi;
  if (!(std > 0.0)) return std::max(improvement, 0.0);
  const double z = improvement / std;
  // Far in the lower tail the two terms cancel to below rounding; EI >= 0.
  return std::max(improvement * NormalCdf(z) + std * NormalPdf(z), 0.0);
}

double ProbabilityOfImprovement(double mean, double std, double best, double xi) {
  const double improvement = best - mean - xi;
  if (!(std > 0.0)) return improvement > 0.0 ? 1.0 : 0.0;
  return NormalCdf(improvement / std);
}

// xi is applied in the GP's standardised output scale, i.e. as
// options.xi * gp.output_scale() in the caller's units.
Eigen::VectorXd MaximiseExpectedImprovement(const GaussianProcess& gp, double best,
                                            const AcquisitionOptions& options, std::mt19937_64& rng,
                                            int threads) {
  CheckAcquisitionOptions(options);
  const int d = gp.dimension();
  const StandardisedEi ei{&gp, (best - gp.output_mean()) / gp.output_scale(), options.xi};

  // Scored in blocks of a fixed size, so the rounding (and the answer) is the
  // same for any thread count.
  const Eigen::MatrixXd candidates = UniformPoints(options.random_candidates, d, rng);
  Eigen::VectorXd score(candidates.rows());
  const Eigen::Index rows = candidates.rows();
  const auto blocks = static_cast<size_t>((rows + kScoringBlock - 1) / kScoringBlock);
  ParallelFor(blocks, threads, [&](size_t b) {
    const Eigen::Index first = static_cast<Eigen::Index>(b) * kScoringBlock;
    const Eigen::Index count = std::min(kScoringBlock, rows - first);
    Eigen::VectorXd mean, std;
    gp.PredictBatch(candidates.middleRows(first, count), mean, std);
    for (Eigen::Index i = 0; i < count; ++i) score(first + i) = ei(mean(i), std(i));
  });

  // Each local refinement keeps its own best; the first of equal bests wins.
  const std::vector<Eigen::Index> top = TopIndices(score, std::max(options.local_starts, 1));
  const size_t starts =
      std::min(static_cast<size_t>(std::max(options.local_starts, 0)), top.size());
  std::vector<LocalSearch> searches;
  for (size_t s = 0; s < std::max<size_t>(starts, 1); ++s) {
    searches.push_back({ei, Eigen::VectorXd(d), candidates.row(top[s]).transpose(), score(top[s])});
  }
  ParallelFor(starts, threads, [&](size_t s) {
    RefineWithBobyqa(candidates.row(top[s]).transpose(), options.local_max_evaluations,
                     searches[s]);
  });
  const LocalSearch& winner = *std::max_element(
      searches.begin(), searches.end(),
      [](const LocalSearch& a, const LocalSearch& b) { return a.best_value < b.best_value; });
  return winner.best_x.cwiseMax(0.0).cwiseMin(1.0);
}

// As for EI, xi is in standard deviations of the observed outputs.
double MaxProbabilityOfImprovement(const GaussianProcess& gp, double best, double xi,
                                   int candidates, std::mt19937_64& rng) {
  if (candidates < 1) {
    throw InputError("MaxProbabilityOfImprovement: candidates must be >= 1, got " +
                     std::to_string(candidates));
  }
  const Eigen::MatrixXd points = UniformPoints(candidates, gp.dimension(), rng);
  Eigen::VectorXd mean, std;
  gp.PredictBatch(points, mean, std);
  const double xi_caller = xi * gp.output_scale();
  double best_probability = 0.0;
  for (Eigen::Index i = 0; i < mean.size(); ++i) {
    best_probability =
        std::max(best_probability, ProbabilityOfImprovement(mean(i), std(i), best, xi_caller));
  }
  return best_probability;
}

}  // namespace boicp
