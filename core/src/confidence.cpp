#include "boicp/confidence.hpp"

#include <cmath>

namespace boicp {
namespace {

// Logistic regression weights from bench/fit_confidence.py, fitted on 210
// bench runs (presets A and C, nested and 6 DOF, automatic settings, every
// dataset at arbitrary headings, two seeds); bench/README.md has how they
// do on runs they were not fitted on.
constexpr double kIntercept = -4.129;
constexpr double kFitness = 12.94;
constexpr double kRmseRatio = -2.775;
constexpr double kMargin = 12.8;
constexpr double kSupport = 0.8901;
constexpr double kProbabilityBetter = 2.459;

}  // namespace

double Confidence(const ConfidenceFeatures& f) {
  const double z = kIntercept + kFitness * f.fitness + kRmseRatio * f.rmse_ratio +
                   kMargin * f.margin + kSupport * f.support +
                   kProbabilityBetter * f.probability_better;
  return 1.0 / (1.0 + std::exp(-z));
}

}  // namespace boicp
