#pragma once
// The registration methods the bench compares: core's, and the baselines on
// the same interface (registration_method.hpp), each under a bench name with
// the dataset's settings. Each gets the raw (perturbed) clouds, so its wall
// time covers all of its preprocessing.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "boicp/registration/bo_icp.hpp"
#include "boicp/registration/confidence.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/registration/registration_method.hpp"
#include "boicp/util/types.hpp"
#include "dataset_table.hpp"

namespace boicp::bench {

struct MethodInput {
  const Points& source;
  const Points& target;
  const DatasetSettings& dataset;
  uint64_t seed = 1;
  int threads = 1;     // the run's thread budget: every method gets the same
  bool quick = false;  // smoke-test budgets (smaller RANSAC and pyramid budgets)
};

struct MethodOutput {
  Transform transform = Transform::Identity();  // T_target_source
  std::optional<double> confidence;             // only methods that report one
  int evaluations = 0;                          // objective evaluations (ICP runs or grid scores)
  size_t source_points = 0;                     // after the method's search downsampling
  size_t target_points = 0;
  double voxel = 0.0;             // the method's search voxel, metres
  std::optional<int> iterations;  // BO: expected-improvement steps per stage
  std::optional<double> icp_s;    // BO only: estimated time inside ICP evaluations
  std::optional<double> model_s;  // BO only: the rest outside refinement (GP fit + acquisition)
  // BO only: what confidence was computed from, searches made and the time of
  // the retries among them.
  std::optional<ConfidenceFeatures> features;
  int attempts = 0;
  double retry_s = 0.0;
  std::string answered_by;               // BO only: RungName of the rung whose answer was kept
  std::vector<Attempt> attempt_details;  // BO only: every attempt, with its answer
};

/// Every method name, in the order tables and plots list them.
const std::vector<std::string>& MethodNames();

/// Runs `name` (one of MethodNames()) on one pair. Throws what the method
/// throws, and UsageError for an unknown name.
MethodOutput RunMethod(const std::string& name, const MethodInput& input);

/// bo-C with `config` as given (fields still automatic chosen from the pair).
MethodOutput RunBoIcpWithConfig(const BoIcpConfig& config, const MethodInput& input);

/// One line per method describing its budget, for summary.md.
std::vector<std::string> DescribeMethods(const std::vector<std::string>& names, bool quick);

/// core's methods (CoreMethods()) and the bench's baselines on the same
/// interface: "naive", "icp-identity", "pyramid", "ransac-fpfh" and "fgr".
/// The baselines prepare nothing (they keep the raw scan) so that their
/// time covers all of their own preprocessing. `quick`: smoke-test budgets.
MethodRegistry BenchRegistry(bool quick);

// The baselines, one file each: raw clouds in, with the dataset table's settings.
RegistrationResult RunNaiveBoIcp(const Points& source, const Points& target,
                                 const BoIcpConfig& config, const RegistrationCallbacks& callbacks);
RegistrationResult RunIcpFromIdentity(const Points& source, const Points& target,
                                      const BoIcpConfig& config);
RegistrationResult RunPyramid(const Points& source, const Points& target, const BoIcpConfig& config,
                              bool quick);
RegistrationResult RunRansacFpfh(const Points& source, const Points& target,
                                 const BoIcpConfig& config, bool quick);
RegistrationResult RunFastGlobal(const Points& source, const Points& target,
                                 const BoIcpConfig& config);

}  // namespace boicp::bench
