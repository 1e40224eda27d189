#pragma once
// One pair's BO search (nested or 6 DOF; whole, or short and then continued
// to the whole budget) and the refinement and assessment of its answers:
// what the fixed budget and every rung of the ladder share (bo_icp.cpp).
// Internal to core.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "boicp/bo/bayes_opt.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "boicp/registration/refinement.hpp"
#include "boicp/registration/search_space.hpp"

namespace boicp {

// Two ICP ends in one basin: within 5 degrees and 3 search voxels.
bool SameBasin(const Transform& a, const Transform& b, double voxel);

// Everything one registration evaluates against, built once per pair.
struct PairContext {
  const PreparedPair& prepared;
  Points evaluation_source;  // subsample of prepared.search_source used by every BO evaluation
  Points coarse_source;      // subsample of evaluation_source for the first part of each ICP run
  IcpOptions search_icp;
};

PairContext MakePairContext(const PreparedPair& prepared, const BoIcpConfig& config);

// Where a pair's searches are anchored: on the prior, or without one on "same
// orientation, centroids on top of each other"; rotations turn the source
// about the pivot, the anchor-mapped source centroid.
struct SearchFrame {
  Transform anchor = Transform::Identity();
  Point pivot = Point::Zero();
  Point source_centroid = Point::Zero();
};

SearchFrame MakeSearchFrame(const PreparedPair& prepared, const std::optional<Transform>& prior);

// Where a search's translation box lies: centred, for each rotation R, on
// pivot - R * source_centroid (the rotation turns the source about the pivot).
struct SearchBox {
  Point pivot = Point::Zero();
  Point source_centroid = Point::Zero();
  Eigen::Vector3d translation_bounds = Eigen::Vector3d::Zero();
};

// RegistrationResult::search_reach of `T` in `box`. An axis the search does
// not move along (bound 0) does not count.
double SearchReach(const SearchBox& box, const Transform& T);

// An answer refined at the finest level and assessed: by a search (with its
// history) or by a rung that refines given starts (history empty).
struct SearchOutcome {
  SearchBox box;
  std::shared_ptr<const PreparedPair> prepared;  // kept for a wider refinement
  RefinedAlignment refined;
  double overlap = 0.0;  // RegistrationResult::overlap of the refined answer
  size_t source_points = 0, target_points = 0;
  double objective = 0.0;  // best search objective
  double probability_better = 0.0;
  double gp_mean = 0.0, gp_std = 0.0;
  std::vector<Evaluation> history;
  ConfidenceFeatures features;
  double confidence = 0.0;
};

// A new outcome of one prepared pair, before anything is refined.
SearchOutcome OutcomeOf(std::shared_ptr<const PreparedPair> prepared, const SearchFrame& frame,
                        const BoIcpConfig& config);

// Refines `starts` (best guess first) to the finest level, compares them
// there and assesses the winner.
void RefineAndAssess(SearchOutcome& out, const std::vector<Transform>& starts,
                     const BoIcpConfig& config, const RegistrationCallbacks& callbacks);

// The `count` best distinct ends of the outcome's search, followed by the
// `learned` answers of earlier rungs that lie in none of their basins.
std::vector<Transform> EndsAndLearned(const SearchOutcome& out, int count, double voxel,
                                      const std::vector<Transform>& learned);

// Refines the `count` best distinct ends of the outcome's search, compares
// them at the finest level and assesses the winner.
void RefineEnds(SearchOutcome& out, int count, const BoIcpConfig& config,
                const RegistrationCallbacks& callbacks);

class SearchStages;

// The nested or 6-DOF search of one pair: run whole, or run short (each stage
// ends once its best basin is confirmed) and later continued to the whole
// budget without repeating an evaluation.
class StagedSearch {
 public:
  StagedSearch(const PairContext& pair, const SearchFrame& frame, const BoIcpConfig& config,
               const RegistrationCallbacks& callbacks);
  ~StagedSearch();

  // The first run (short or whole); `seeds` (T_target_source, earlier
  // answers) join the first stage's initial samples.
  void Start(bool short_budget, const std::vector<Transform>& seeds = {});

  // The rest of a short run, to the whole budget.
  void Continue() { Run(false); }

  // The search's best ends and the surrogate's view of them.
  void Report(SearchOutcome& out) const;

  int evaluations() const;

 private:
  SearchSpace FirstSpace() const;
  void Run(bool short_budget);

  std::unique_ptr<SearchStages> search_;
  const SearchFrame frame_;
  const BoIcpConfig& config_;
  std::vector<Eigen::VectorXd> first_starts_;
  BayesOptResult first_, second_;
  std::optional<Transform> second_from_;  // the end the translation box was centred on
  const BayesOptResult* last_ = nullptr;
  double probability_better_ = 0.0;
};

// One whole search from the pair's own prepared clouds, its
// refine_candidates best distinct ends refined and assessed. The finer
// levels are subsampled with `level_seed` (default config.seed), so a retry
// with another seed scores its answer on the first search's points.
SearchOutcome SearchAndRefine(const ScanPyramid& source, const ScanPyramid& target,
                              const BoIcpConfig& config, const std::optional<Transform>& prior,
                              const RegistrationCallbacks& callbacks,
                              std::optional<uint64_t> level_seed = std::nullopt);

// A doubtful answer may be a basin that only looked best on coarse voxels
// (a low-overlap view slid along a wall scores like the true one there),
// while the true one, visited by the same search, ranked below the few
// refined. The retry first compares this many of the search's distinct ends
// at the finest level.
constexpr int kWiderRefinementEnds = 8;

// The retry of a doubtful search: in 6 DOF, with another seed, and at
// config.retry_voxel when set. The finest refinement level stays, so both
// answers' fitness is measured alike.
BoIcpConfig RetryConfig(const BoIcpConfig& config);

}  // namespace boicp
