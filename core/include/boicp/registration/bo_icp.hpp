#pragma once
// BO-ICP: Bayesian optimisation over ICP's initial transform (Biggie,
// Beathard, Heckman), nested (rotation, then translation) or in 6 DOF,
// followed by a fine ICP refinement.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "boicp/icp/pair_information.hpp"
#include "boicp/icp/unconstrained_slides.hpp"
#include "boicp/registration/confidence.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

struct ScanPyramid;  // refinement.hpp

/// One ICP run started by the search. A run that reached the end of an
/// earlier converged run (BoIcpConfig::join_converged_runs) reports that end
/// and its objective.
struct Evaluation {
  int stage = 0;                              // 0 = rotation / joint, 1 = translation
  Transform initial = Transform::Identity();  // T0 that BO proposed
  Transform result = Transform::Identity();   // where ICP took it
  double objective = 0.0;                     // truncated mean distance after ICP, metres
};

/// The rungs of the escalation ladder (Budget::kAuto), cheapest first. Each
/// runs only while the answers before it are doubtful; a fixed budget runs
/// the full search and the retry only.
enum class Rung {
  kPrior,        ///< the refinement from the pair's prior (or a drive's identity guess), beside
                 ///< probes around it and the feature hypotheses
  kFeatures,     ///< FPFH correspondence hypotheses, refined (without a prior or guess)
  kShortSearch,  ///< the search, each stage ending once its best basin is confirmed
  kFullSearch,   ///< the same search continued to the preset's full budget
  kRetry,        ///< a 6-DOF search with another seed, seeded with what came before
};

/// "prior", "features", "short-search", "full-search" or "retry".
std::string RungName(Rung rung);

/// What one attempt of a registration did.
enum class AttemptKind {
  kPrior,        ///< the prior rung's refinement
  kFeatures,     ///< the feature rung's hypotheses, refined
  kShortSearch,  ///< a search whose stages stop once their best basin is confirmed
  kSearch,  ///< a BO search (or the rest of a short one) and the refinement of its best distinct
            ///< ends
  kWiderRefinement,  ///< more distinct ends of the first search refined and compared
};

/// "prior", "features", "short-search", "search" or "wider-refinement".
std::string AttemptKindName(AttemptKind kind);

/// One attempt of a registration: a rung of the ladder, or for a fixed
/// budget the search, and for a doubtful answer a wider refinement of that
/// search and then a second search.
struct Attempt {
  AttemptKind kind = AttemptKind::kSearch;
  SearchMode mode = SearchMode::kNested;
  uint64_t seed = 0;
  double fitness = 0.0;  // inlier fraction of its refined answer at the finest level
  double confidence = 0.0;
  int evaluations = 0;   // ICP runs it made (search evaluations, or refined starts)
  int refined_ends = 0;  // distinct starts compared at the finest level, at most
  double runtime_s = 0.0;
  bool kept = false;                            // its answer is the result's
  Transform transform = Transform::Identity();  // its answer, T_target_source
  ConfidenceFeatures features;                  // what its confidence came from
};

/// A result is trusted when its confidence, its estimated probability of
/// being right, is at least this, and doubtful below it: a wrong answer
/// trusted once in twenty is the most a map can take, and the ladder tries
/// its next rung until an answer reaches it.
constexpr double kTrustedFrom = 0.95;

/// Result of registering one pair. Frame convention: `transform` is
/// T_target_source, so p_target = transform * p_source (metres, radians).
struct RegistrationResult {
  Transform transform = Transform::Identity();
  /// Best search objective (truncated mean NN distance, metres); for an
  /// answer of the prior or feature rung, that objective at the answer.
  double objective = 0.0;
  double fitness = 0.0;      // fraction of refined source points within inlier_distance
  double inlier_rmse = 0.0;  // RMS distance of those points, metres
  /// How firmly those inliers pin down `transform` (PlaneInformation over
  /// the refined source points, within inlier_distance): a pose graph's edge
  /// weight, weak along directions the surfaces do not constrain.
  InformationMatrix information = InformationMatrix::Zero();
  /// The slides those inliers leave free (UnconstrainedSlides),
  /// axes in the target's frame; an answer with one is doubtful
  /// (features.constrained_share caps its confidence).
  std::vector<FreeSlide> unconstrained;
  /// Fraction of the search-voxel source within 1.5 search voxels of the
  /// target: how much of the source the target sees, for keyframe choice.
  double overlap = 0.0;
  /// How far into the search's translation box the answer lies: the largest
  /// offset from the box's centre over the axes, each as a fraction of that
  /// axis's bound (above 1: outside the box). The box is centred on the prior,
  /// or without one on the clouds' centroids, so this says how far a drive's
  /// next scan may be from what the search can reach.
  double search_reach = 0.0;
  /// Estimated probability, in [0,1], that `transform` is within the success
  /// thresholds (2 degrees, and a few refinement voxels).
  double confidence = 0.0;
  bool doubtful = false;            // confidence < kTrustedFrom
  ConfidenceFeatures features;      // what confidence was computed from
  double gp_mean = 0.0;             // GP posterior mean at the optimum (last stage), metres
  double gp_std = 0.0;              // GP posterior standard deviation there, metres
  double probability_better = 0.0;  // max over stages of the GP's P(some other point is better)
  int evaluations = 0;              // ICP runs of every attempt together
  Rung answered_by = Rung::kFullSearch;  // the rung whose answer was kept
  double runtime_s = 0.0;                // wall time of RegisterPair, retries included
  size_t source_points = 0;              // after search downsampling
  size_t target_points = 0;
  std::vector<Evaluation> history;  // of the kept search
  std::vector<Attempt> attempts;    // every search made, first first
  /// The settings used, automatic fields resolved, and the names of those
  /// chosen from the clouds.
  BoIcpConfig config;
  std::vector<std::string> auto_fields;
};

struct RegistrationProgress {
  std::string stage;  // "rotation", "translation", "6dof" or "refine"
  int done = 0;       // evaluations finished in this stage
  int total = 0;      // evaluations planned in this stage
  double best_objective = 0.0;
};

struct RegistrationCallbacks {
  std::function<void(const RegistrationProgress&)> progress;
  std::function<bool()> stop_requested;  // polled between rounds; true -> boicp::Cancelled
  /// Replaces the ICP run inside each search evaluation, for baselines that
  /// measure another ICP implementation against the same search (called from
  /// config.threads threads at once, so it must be thread-safe): aligns
  /// `source` onto `target` from `initial` and returns T_target_source. Empty:
  /// core's ICP (config.icp_objective) against the prebuilt target index.
  std::function<Transform(const Points& source, const Points& target, const Transform& initial)>
      local_icp;
};

/// Registers `source` onto `target` (raw clouds in their sensor frames).
/// Fields still in config.automatic are first chosen from the two clouds
/// (auto_settings.hpp). `prior`, when given (for example odometry), centres
/// the search box and is the first sample. With Budget::kAuto the rungs of
/// the ladder (Rung) run in turn until one answer is trusted: the prior rung
/// starts from `prior`, or without one from `guess` (for example identity for
/// consecutive scans of a drive; unlike a prior it does not move the search
/// box). A doubtful answer is searched for once more when
/// config.retry_when_doubtful. Throws InputError for an
/// invalid config, a cloud too small to choose settings from or left empty by
/// cropping/downsampling, and Cancelled when stop_requested fires.
RegistrationResult RegisterPair(const Points& source, const Points& target,
                                const BoIcpConfig& config,
                                const std::optional<Transform>& prior = std::nullopt,
                                const RegistrationCallbacks& callbacks = {},
                                const std::optional<Transform>& guess = std::nullopt);

/// The same for scans cropped and downsampled beforehand (BuildScanPyramid
/// with this config), which pairs that share a scan share: the same answer
/// as RegisterPair on the raw scans. runtime_s leaves out building the
/// pyramids. Throws std::invalid_argument when config.automatic is not
/// empty (the settings must be chosen first) or a pyramid was cut to other
/// range limits.
RegistrationResult RegisterPair(const ScanPyramid& source, const ScanPyramid& target,
                                const BoIcpConfig& config, const std::optional<Transform>& prior,
                                const RegistrationCallbacks& callbacks = {},
                                const std::optional<Transform>& guess = std::nullopt);

/// ICP alone: one refinement from `start` (T_target_source) through the
/// pyramid's levels, its answer assessed like every other (confidence,
/// fitness, information), for scans already close to aligned. Answered by
/// Rung::kPrior with one attempt and one evaluation. Throws
/// std::invalid_argument when config.automatic is not empty, InputError for
/// an invalid config, and Cancelled when stop_requested fires.
RegistrationResult RefineFromStart(const ScanPyramid& source, const ScanPyramid& target,
                                   const BoIcpConfig& config, const Transform& start,
                                   const RegistrationCallbacks& callbacks = {});

}  // namespace boicp
