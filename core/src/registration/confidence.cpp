#include "boicp/registration/confidence.hpp"

#include <algorithm>
#include <cmath>

#include "boicp/icp/unconstrained_slides.hpp"

namespace boicp {
namespace {

// Logistic regression weights from bench/fit_confidence.py, fitted on bench
// runs (presets A and C, nested and 6 DOF, every dataset at arbitrary
// headings, automatic and fixed settings); bench/README.md has how they do
// on runs they were not fitted on. The other features did not separate
// held-out runs better (see the script), so they carry no weight.
constexpr double kIntercept = 3.128;
constexpr double kFitness = 26.6;
constexpr double kLogMargin = 3.38;
constexpr double kResolutionDeg = -6.037;
// The margin enters as log(margin + kMarginFloor): a near tie is what marks a
// wrong basin, and the log tells a 2 % margin from a 15 % one where a linear
// term barely does. The floor is about the precision of a fitness.
constexpr double kMarginFloor = 0.01;
// Two basins whose fitnesses differ by no more than that precision are a
// tie, and the data cannot say which is right: a measured margin is trusted
// from none at kMarginFloor to full at kMarginOfFullTrust, whatever the fit.
// The log term alone lets a high fitness outweigh a tie (bench/README.md
// has the margins of right and wrong answers).
constexpr double kMarginOfFullTrust = 0.03;
// An answer that matches few of the source's points is trusted at most in
// proportion to them, whatever the model says: between two near-empty fits
// the margin is a ratio of noise, and with no inliers nothing supports the
// answer. Under half this fitness an answer is always doubtful. Right
// answers match far more (bench/README.md).
constexpr double kFitnessOfFullTrust = 0.1;
// An answer that moves its points into space the target's sensor saw
// through is wrong unless the scene moved: trust falls from full at 15 % of
// the points to none at 30 %. A right answer's share is what moved between
// the scans plus sampling at depth edges, a few per cent; a street turned
// half round puts a third of its points there (bench/README.md).
constexpr double kSeenThroughOfFullTrust = 0.15;
// An answer free to slide along some direction (a corridor, a floor, a
// wall) is right only by chance along it: trust falls from full just above
// kUnconstrainedShare (a slide of 10 inlier distances moves the matches off
// their surfaces by one, on average), so that every answer with an
// unconstrained slide is doubtful, to none at half that. Right answers of
// real scans hold their weakest slide more firmly (bench/README.md).
constexpr double kConstrainedShareOfFullTrust = 1.06 * kUnconstrainedShare;
constexpr double kConstrainedShareOfNoTrust = 0.5 * kUnconstrainedShare;
// An answer whose fit survives a slide off it (slide_rival near 1) is one
// spot of many where its surfaces fit: a street's ground and facades fit a
// block further on as well. Trust falls from full at kSlideRivalOfFullTrust
// to none at kSlideRivalOfNoTrust. Right answers keep less of their fit;
// bench/README.md has both sides and how the line does on each dataset
// held out.
constexpr double kSlideRivalOfFullTrust = 0.88;
constexpr double kSlideRivalOfNoTrust = 0.92;

// A cap that rises linearly from 0 where `value` is `no_trust` to 1 where it
// is `full_trust` (either way round), and stays there beyond.
double TrustBetween(double value, double no_trust, double full_trust) {
  return std::clamp((value - no_trust) / (full_trust - no_trust), 0.0, 1.0);
}

}  // namespace

double Confidence(const ConfidenceFeatures& f) {
  const double z = kIntercept + kFitness * f.fitness +
                   kLogMargin * std::log(f.margin + kMarginFloor) +
                   kResolutionDeg * f.resolution_deg;
  const double model = 1.0 / (1.0 + std::exp(-z));
  const double tie_cap =
      f.margin_measured ? TrustBetween(f.margin, kMarginFloor, kMarginOfFullTrust) : 1.0;
  const double seen_through_cap =
      TrustBetween(f.seen_through, kSeenThroughOfNoTrust, kSeenThroughOfFullTrust);
  const double free_slide_cap =
      TrustBetween(f.constrained_share, kConstrainedShareOfNoTrust, kConstrainedShareOfFullTrust);
  const double slide_rival_cap =
      TrustBetween(f.slide_rival, kSlideRivalOfNoTrust, kSlideRivalOfFullTrust);
  return std::min({model, std::max(f.fitness, 0.0) / kFitnessOfFullTrust, tie_cap, seen_through_cap,
                   free_slide_cap, slide_rival_cap});
}

}  // namespace boicp
