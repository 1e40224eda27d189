#pragma once
// One row of results.csv: one method on one pair (or one scaling point).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "boicp/registration/confidence.hpp"

namespace boicp::bench {

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
  std::string error;                           // what the method threw, if it did
};

/// The CSV text: a header line, then one line per row. NaN and absent values
/// are empty fields; commas and quotes in text fields are quoted.
std::string FormatResultsCsv(const std::vector<ResultRow>& rows);

}  // namespace boicp::bench
