#pragma once
// One configuration struct for a BO-ICP registration, with the paper's presets.

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "boicp/bayes_opt.hpp"

namespace boicp {

enum class SearchMode {
  kNested,  // rotation (roll, pitch, yaw) first, then translation with that rotation fixed
  kSixDof,  // all six degrees of freedom in one search
};

SearchMode ParseSearchMode(const std::string& name);  // "nested" | "6dof"; throws InputError
std::string SearchModeName(SearchMode mode);

/// The library's BO settings with 1000 EI candidates per proposal (see
/// BoIcpConfig::bo).
BayesOptOptions RegistrationBayesOptOptions();

struct BoIcpConfig {
  std::string preset = "C";  // name of the preset these values started from

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

  // --- ICP run by every evaluation ----------------------------------------
  double max_correspondence_distance = 0.0;  // metres; 0 = 3 x voxel
  // Clipping distance tau of the objective (truncated mean NN distance),
  // metres; 0 = 1.5 x voxel. Tighter than the ICP gate so that a larger but
  // looser overlap (a view slid along a wall) does not outscore the true one.
  double objective_truncation = 0.0;
  int icp_max_iterations = 60;  // per evaluation; fewer shrink the basin each start reaches
  // Source points (random, seeded) each evaluation uses; 0 = all. 2000 is
  // the fewest that kept every real-data test pair that 3000 did: 1500 lost
  // the 40 %-overlap 7-Scenes pair 450->475, 1000 a bench pair.
  size_t evaluation_points = 2000;
  // Each evaluation's ICP first runs on this many of those points (random,
  // seeded), where a step costs half, then finishes on all of them with the
  // iterations left of icp_max_iterations, but at least
  // finish_icp_iterations; its end is scored on all of them. 0 = the whole run
  // on evaluation_points. Measured on the bench: 1000 kept 17/17 7-Scenes
  // pairs at 1.55 s; 750 lost one and 500 two (500 was 25 % faster on KITTI).
  size_t coarse_icp_points = 1000;
  // 5 finishing iterations instead of 10 cut the 7-Scenes ICP time by 14 %,
  // with the same successes over the bench's 35 pairs at three seeds.
  int finish_icp_iterations = 5;
  // An evaluation whose ICP comes within half a voxel and 0.01 rad of where
  // an earlier one converged stops and takes over that end and its score
  // (IcpOptions::join_translation): measured, a quarter less ICP work with
  // the same ends. Off: every evaluation runs its ICP to its own end.
  bool join_converged_runs = true;
  // Stop an evaluation's ICP in a translation-only stage once its projected
  // end cannot beat the best objective found before its round
  // (IcpOptions::abandon_above). Off: measured on the bench it saved about a
  // fifth of the search time but lost the true basin of the hardest bunny
  // pair, whose right start slides slowly before it snaps into place.
  bool abandon_hopeless = false;

  // --- Final refinement of the best candidate ------------------------------
  double refine_voxel = 0.0;  // metres, finest level of the refinement pyramid; 0 = voxel / 4
  int refine_max_iterations = 60;
  int refine_candidates = 3;  // distinct best search results refined; the best fit at the end wins
  // Source points (random, seeded) ICP uses at each level finer than the
  // search voxel; 0 = all. A 7-Scenes frame still has 30,000 or more at
  // 1.25 cm; 10,000 halved the refinement time with the same accuracy on the
  // bench pairs.
  size_t refine_source_points = 10000;
  double inlier_distance =
      0.0;  // metres, for fitness / inlier_rmse / confidence; 0 = 1.5 x refine voxel

  // --- Preprocessing --------------------------------------------------------
  double min_range = 0.0;  // metres from the sensor; points closer are dropped
  double max_range = 0.0;  // metres; 0 = no limit

  // --- Surrogate and acquisition ----------------------------------------------
  // random_samples / iterations are copied into it per stage. 1000 uniform EI
  // candidates per proposal instead of the library's 2000: a nested stage
  // searches 3 dimensions, and BOBYQA refines the best five anyway. Over the
  // bench's 35 pairs at three seeds (with finish_icp_iterations 5) the
  // surrogate's time fell by about a third with as many successes.
  BayesOptOptions bo = RegistrationBayesOptOptions();

  uint64_t seed = 1;  // drives the initial design, subsampling and acquisition
  // ICP runs of one BO round (config.bo.batch_size of them) that run at once.
  // The answer does not depend on it.
  int threads = 1;

  // Derived values (the "0 = auto" rules above).
  double EffectiveMaxCorrespondence() const;
  double EffectiveTruncation() const;
  double EffectiveRefineVoxel() const;
  double EffectiveInlierDistance() const;
};

/// Preset "A" (10 random / 20 iterations / 0.7 m), "B" (20 / 35 / 0.7) or
/// "C" (30 / 60 / 0.6), from the paper; case-insensitive. Throws InputError.
BoIcpConfig PresetConfig(const std::string& name);

/// Throws InputError naming the first invalid field (non-positive voxel,
/// negative or non-finite bounds, all bounds zero, N_r < 1, ...).
void ValidateConfig(const BoIcpConfig& config);

}  // namespace boicp
