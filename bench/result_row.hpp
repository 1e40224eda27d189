#pragma once
// One row of results.csv: one method on one pair (or one scaling point).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "boicp/registration/confidence.hpp"

namespace boicp::bench {

/// One attempt of a BO registration, judged like a method's answer: the
/// samples bench/fit_confidence.py fits the confidence on, from every rung.
struct AttemptRow {
  std::string kind;  // AttemptKindName
  std::string mode;  // SearchModeName
  ConfidenceFeatures features;
  double confidence = 0.0;
  bool success = false;
  bool kept = false;
};

struct ResultRow {
  std::string experiment = "suite";  // "suite", "scaling-voxel" or "scaling-iterations"
  std::string dataset;
  std::string source;
  std::string target;
  std::string method;
  int threads = 1;
  uint64_t seed = 0;  // the seed the method ran with
  std::string perturb;
  double voxel = 0.0;             // the method's search voxel
  std::optional<int> iterations;  // BO: N per stage
  size_t source_points = 0;       // after the method's search downsampling
  size_t target_points = 0;
  int evaluations = 0;
  double wall_s = 0.0;
  double rot_err_deg = 0.0;  // NaN when the method threw
  double trans_err_m = 0.0;
  double mean_p2p_m = 0.0;
  double overlap = 0.0;
  bool success = false;
  std::optional<double> confidence;
  std::optional<double> icp_s;
  std::optional<double> model_s;
  std::optional<ConfidenceFeatures> features;  // BO only
  int attempts = 0;                            // BO only: searches made (2 = retried)
  double retry_s = 0.0;                        // BO only: wall time of the retry, in wall_s
  std::string answered_by;                     // BO only: the rung whose answer was kept
  std::string error;                           // what the method threw, if it did
  std::vector<AttemptRow> attempt_rows;        // BO only
};

/// The CSV text: a header line, then one line per row. NaN and absent values
/// are empty fields; commas and quotes in text fields are quoted.
std::string FormatResultsCsv(const std::vector<ResultRow>& rows);

/// attempts.csv: one line per attempt of every BO row (dataset, pair, method,
/// the attempt's kind and mode, its confidence features, its confidence,
/// whether its own answer met the dataset's success thresholds, and whether
/// it was kept).
std::string FormatAttemptsCsv(const std::vector<ResultRow>& rows);

}  // namespace boicp::bench
