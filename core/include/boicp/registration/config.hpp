#pragma once
// One configuration struct for a BO-ICP registration, with the paper's presets.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "boicp/bo/bayes_opt.hpp"

namespace boicp {

enum class SearchMode {
  kNested,  // rotation (roll, pitch, yaw) first, then translation with that rotation fixed
  kSixDof,  // all six degrees of freedom in one search
};

/// How a search box that holds every rotation names them (search_space.hpp).
/// Euler angles are the paper's box; a rotation vector about the anchor has
/// no gimbal lock, and its kernel measures the angle between two rotations.
enum class RotationCoordinates { kEulerAngles, kRotationVector };

SearchMode ParseSearchMode(const std::string& name);  // "nested" | "6dof"; throws InputError
std::string SearchModeName(SearchMode mode);

/// The ICP objective of every search evaluation.
enum class IcpObjective {
  kPointToPoint,  // distances to the matched points (the paper's)
  kPointToPlane,  // distances to the matched points' tangent planes (target normals)
};

IcpObjective ParseIcpObjective(const std::string& name);  // "point" | "plane"; throws InputError
std::string IcpObjectiveName(IcpObjective objective);

/// How much a registration may spend on a pair.
enum class Budget {
  /// An escalation ladder (bo_icp.hpp): cheap rungs first, each later rung
  /// only while the answer is doubtful.
  kAuto,
  /// The paper's search: the preset's full budget, then the retry of a
  /// doubtful answer; no prior or feature rung, no stopping rule.
  kFixed,
};

Budget ParseBudget(const std::string& name);  // "auto" | "fixed"; throws InputError
std::string BudgetName(Budget budget);

/// The kind of sensor a scan comes from, which sets the rotation box, the
/// map's up and the overlap that pairs keyframes.
enum class SensorKind { kLidar, kDepthCamera, kOther };
std::string SensorKindName(SensorKind kind);  // "lidar" | "depth camera" | "other"

/// The --sensor setting: "lidar", "depth" or "object" (kOther), or "auto"
/// (nullopt: from the file format, else from the scans' geometry). Throws
/// InputError naming the choices.
std::optional<SensorKind> ParseSensorSetting(const std::string& name);
std::string SensorSettingName(const std::optional<SensorKind>& sensor);

/// The library's BO settings with 1000 EI candidates per proposal (see
/// BoIcpConfig::bo).
BayesOptOptions RegistrationBayesOptOptions();

/// The registration fields automatic settings may choose (auto_settings.hpp),
/// by the names reported in "auto".
extern const std::vector<std::string> kAutoRegistrationFields;

/// Snaps roll and yaw half-widths within 1e-3 of pi to pi, and a pitch
/// half-width within 1e-3 of pi/2 to pi/2, so that a bound typed as 3.1416
/// still wraps around.
Eigen::Vector3d SnapRotationBounds(const Eigen::Vector3d& bounds);

/// The registration method front ends use unless told otherwise
/// (registration_method.hpp).
inline constexpr const char* kDefaultMethod = "bo-icp";

struct BoIcpConfig {
  /// The registration method, by its name in the registry (CoreMethods());
  /// the fields below are its settings.
  std::string method = kDefaultMethod;
  std::string preset = "C";  // name of the preset these values started from
  /// Fields still to be chosen from the clouds (names from
  /// kAutoRegistrationFields); their values below are the preset's fixed ones
  /// until then. RegisterPair chooses them from the pair; a batch chooses them
  /// once (ChooseSettingsForClouds) and clears the list. Empty: every value
  /// as set (--fixed-settings).
  std::vector<std::string> automatic = kAutoRegistrationFields;
  /// Removes `field` from `automatic`: the user set it.
  void MarkSet(const std::string& field);

  Budget budget = Budget::kAuto;
  /// The sensor as the user set it; nullopt: the file format says, else the
  /// scans' geometry (auto_settings.hpp).
  std::optional<SensorKind> sensor;

  // --- Search (the paper's N_r, N and voxel) -------------------------------
  int random_samples = 30;  // N_r: space-filling samples per search stage
  int iterations = 60;      // N: expected-improvement steps per search stage
  double voxel = 0.6;       // metres: both clouds are downsampled to this for the search
  SearchMode mode = SearchMode::kNested;

  // Half-widths of the search box. Rotations are offsets (roll about x, pitch
  // about y, yaw about z; R = Rz Ry Rx) applied about the source centroid;
  // translations are offsets from the translation that puts the source
  // centroid on the target centroid (or from the prior, when one is given).
  // Pitch is capped at pi/2: with roll and yaw spanning +-pi that covers every
  // rotation exactly once, so no rotation appears twice in the box.
  Eigen::Vector3d rotation_bounds{M_PI, M_PI / 2, M_PI};  // radians (roll, pitch, yaw)
  Eigen::Vector3d translation_bounds{4.0, 2.0, 1.0};      // metres (x, y, z), the paper's
  // How a box holding every rotation names them; nullopt: rotation vectors on
  // the ladder, the paper's Euler angles on the fixed budget. A narrower box
  // (a LiDAR's level, any heading) is always in Euler angles.
  std::optional<RotationCoordinates> rotation_coordinates;

  // --- ICP run by every evaluation ----------------------------------------
  IcpObjective icp_objective = IcpObjective::kPointToPlane;
  double max_correspondence_distance = 0.0;  // metres; 0 = 3 x voxel
  // Clipping distance tau of the objective (truncated mean NN distance),
  // metres; 0 = 1.5 x voxel. Tighter than the ICP gate so that a larger but
  // looser overlap (a view slid along a wall) does not outscore the true one.
  double objective_truncation = 0.0;
  int icp_max_iterations = 60;  // per evaluation; fewer shrink the basin each start reaches
  // Source points (random, seeded) each evaluation uses; 0 = all. Fewer lose
  // the true basin of low-overlap pairs.
  size_t evaluation_points = 2000;
  // Each evaluation's ICP first runs on this many of those points (random,
  // seeded), where a step costs half, then finishes on all of them with the
  // iterations left of icp_max_iterations, but at least
  // finish_icp_iterations; its end is scored on all of them. 0 = the whole run
  // on evaluation_points.
  size_t coarse_icp_points = 1000;
  int finish_icp_iterations = 5;
  // An evaluation whose ICP comes within half a voxel and 0.01 rad of where
  // an earlier one converged stops and takes over that end and its score
  // (IcpOptions::join_translation): a run that far in cannot leave the basin.
  // Off: every evaluation runs its ICP to its own end.
  bool join_converged_runs = true;

  // --- Final refinement of the best candidate ------------------------------
  double refine_voxel = 0.0;  // metres, finest level of the refinement pyramid; 0 = voxel / 4
  int refine_max_iterations = 60;
  int refine_candidates = 3;  // distinct best search results refined; the best fit at the end wins
  // Source points (random, seeded) ICP uses at each level finer than the
  // search voxel; 0 = all. Beyond 10,000 the refined pose no longer improves.
  size_t refine_source_points = 10000;
  double inlier_distance =
      0.0;  // metres, for fitness / inlier_rmse / confidence; 0 = 1.5 x refine voxel

  // --- Preprocessing --------------------------------------------------------
  double min_range = 0.0;  // metres from the sensor; points closer are dropped
  double max_range = 0.0;  // metres; 0 = no limit

  // --- Surrogate and acquisition ----------------------------------------------
  // random_samples / iterations are copied into it per stage. 1000 uniform EI
  // candidates per proposal instead of the library's 2000: a nested stage
  // searches 3 dimensions, and BOBYQA refines the best five anyway.
  BayesOptOptions bo = RegistrationBayesOptOptions();

  // --- Checking the answer ---------------------------------------------------
  // A doubtful first answer (confidence < kTrustedFrom) is tried again:
  // first the search's 8 best distinct ends (instead of refine_candidates)
  // are compared at the finest level; if the answer is still doubtful, one
  // more search runs in 6 DOF (a nested search commits to one rotation
  // before it looks at translations), with another seed, at retry_voxel.
  // The extra budget is those refinements and one search of the same N_r
  // and N. The better fit at the same finest level is kept.
  bool retry_when_doubtful = true;
  // Budget::kAuto: whether a doubtful answer goes on past the short search
  // to the full search and the retry. A bridge or loop candidate does not:
  // the chain puts it within reach of its prior, and on the shared drives
  // every one trusted was answered by the prior or feature rung, while the
  // untrusted ones cost the whole ladder.
  bool full_search_when_doubtful = true;
  // Search voxel of the retry, metres; 0 = voxel. Automatic settings make it
  // coarser than the first search's: a smoother objective with wider basins,
  // which finds the pairs (low overlap, large turns) a fine one misses.
  double retry_voxel = 0.0;

  uint64_t seed = 1;  // drives the initial design, subsampling and acquisition
  // ICP runs of one BO round (config.bo.batch_size of them) that run at once.
  // The answer does not depend on it.
  int threads = 1;

  // Derived values (the "0 = auto" rules above).
  double EffectiveMaxCorrespondence() const;
  double EffectiveTruncation() const;
  double EffectiveRefineVoxel() const;
  double EffectiveInlierDistance() const;
  RotationCoordinates EffectiveRotationCoordinates() const;
};

/// Preset "A" (10 random / 20 iterations / 0.7 m), "B" (20 / 35 / 0.7) or
/// "C" (30 / 60 / 0.6), from the paper; case-insensitive. Throws InputError.
BoIcpConfig PresetConfig(const std::string& name);

/// Throws InputError naming the first invalid field (non-positive voxel,
/// negative or non-finite bounds, all bounds zero, N_r < 1, ...).
void ValidateConfig(const BoIcpConfig& config);

}  // namespace boicp
