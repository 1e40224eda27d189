#pragma once
// Command line of boicp-bench. Scripts rely on:
//   --pairs CSV[,CSV...] --methods M[,M...] --perturb yaw|axis90|none --seed N
//   --threads T --out DIR [--voxel V --translation-bounds X,Y,Z --auto-settings
//   --no-retry]

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "evaluation.hpp"
#include "field_conditions.hpp"

namespace boicp::bench {

/// A malformed command line; main prints the message on one line and exits 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Values that replace the dataset table's entry for every selected dataset.
struct DatasetOverrides {
  std::optional<PerturbationKind> perturb;
  std::optional<double> max_angle_deg;  // axis perturbation only
  std::optional<double> voxel;
  std::optional<Eigen::Vector3d> rotation_bounds;
  std::optional<Eigen::Vector3d> translation_bounds;
  std::optional<double> max_rot_deg;  // success thresholds
  std::optional<double> max_trans_m;
  bool automatic_settings = false;      // BO methods choose voxel and boxes from the clouds
  bool retry_when_doubtful = true;      // BO methods search again when doubtful
  std::string icp_objective = "plane";  // BO methods' search evaluations: plane | point
  FieldCondition field = FieldCondition::kClean;  // applied to every loaded pair
};

struct BenchOptions {
  std::vector<std::string> pairs_csvs;
  std::vector<std::string> methods;  // validated, in the canonical order
  DatasetOverrides overrides;
  uint64_t seed = 1;
  int threads = 1;
  std::string out_dir;
  std::string data_root;  // for --datasets
  int max_pairs = 0;      // per dataset; 0 = every pair
  int synthetic_pairs = 0;
  bool quick = false;
  std::vector<std::string> scaling_datasets;  // dataset names to run the scaling study on
  bool scaling_only = false;                  // run the scaling study and skip the suite
  std::string command_line;
  bool help = false;
  std::string usage;  // the help text, for --help
};

/// Parses argv (CLI11; a flag given twice keeps its last value, except
/// --pairs, whose lists add up). Throws UsageError for unknown flags or
/// methods, missing or malformed values, and a run with no pairs or no --out.
BenchOptions ParseBenchOptions(int argc, const char* const* argv);

}  // namespace boicp::bench
