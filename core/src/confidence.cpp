#include "boicp/confidence.hpp"

#include <cmath>

namespace boicp {
namespace {

// Logistic regression weights, from bench/fit_confidence.py.
constexpr double kIntercept = -4.0;
constexpr double kFitness = 8.0;
constexpr double kRmseRatio = -2.0;
constexpr double kMargin = 3.0;
constexpr double kSupport = 2.0;
constexpr double kProbabilityBetter = -2.0;

}  // namespace

double Confidence(const ConfidenceFeatures& f) {
  const double z = kIntercept + kFitness * f.fitness + kRmseRatio * f.rmse_ratio +
                   kMargin * f.margin + kSupport * f.support +
                   kProbabilityBetter * f.probability_better;
  return 1.0 / (1.0 + std::exp(-z));
}

}  // namespace boicp
