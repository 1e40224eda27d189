
#include "boicp/registration/bo_icp.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <utility>

#include "boicp/registration/alignment_score.hpp"
#include "boicp/registration/auto_settings.hpp"
#include "boicp/registration/feature_hypotheses.hpp"
#include "boicp/registration/fpfh_features.hpp"
#include "boicp/registration/icp.hpp"
#include "boicp/registration/nearest_neighbors.hpp"
#include "boicp/registration/preprocess.hpp"
#include "boicp/registration/refinement.hpp"
#include "boicp/registration/search_space.hpp"
#include "boicp/registration/surface_normals.hpp"

namespace boicp {
namespace {

// Distinct seeds for the independent random choices of one registration.
constexpr uint64_t kSubsampleSalt = 0x9e3779b97f4a7c15ULL;
constexpr uint64_t kStageSalt = 0xbf58476d1ce4e5b9ULL;
constexpr uint64_t kCoarseSalt = 0x94d049bb133111ebULL;
constexpr uint64_t kFeatureSalt = 0xd1b54a32d192ed03ULL;

// Two ICP ends in one basin: within 5 degrees and 3 search voxels.
bool SameBasin(const Transform& a, const Transform& b, double voxel) {
  const Transform delta = a.inverse() * b;
  return RotationAngle(delta) < 5.0 * M_PI / 180.0 && TranslationNorm(delta) < 3.0 * voxel;
}

// A short search stage ends once this many of its runs, out of at least
// kMinShortStageRuns, ended in its best basin: ICP from that many starts
// agrees on it.
constexpr int kConfirmingRuns = 5;
constexpr int kMinShortStageRuns = 10;

// Everything one registration evaluates against, built once per pair.
struct PairContext {
  const PreparedPair& prepared;
  Points evaluation_source;  // subsample of prepared.search_source used by every BO evaluation
  Points coarse_source;      // subsample of evaluation_source for the first part of each ICP run
  IcpOptions search_icp;
};

class Search {
  struct Finished {
    Eigen::VectorXd x;
    Evaluation evaluation;
    bool converged;  // its end may be joined by later runs
  };

 public:
  Search(const PairContext& pair, const BoIcpConfig& config, const RegistrationCallbacks& callbacks)
      : pair_(pair), config_(config), callbacks_(callbacks) {}

  // Runs one BO stage over `space`; the box centre (the anchor) is the first
  // sample, followed by `extra_starts` (unit coordinates). A short stage
  // ends once kConfirmingRuns of its runs ended in its best basin; `resume`
  // continues a stage that ended so, over the same space.
  BayesOptResult RunStage(int stage, const SearchSpace& space, const std::string& name,
                          const std::vector<Eigen::VectorXd>& extra_starts = {},
                          bool short_stage = false, std::vector<BayesOptSample> resume = {}) {
    BayesOptOptions options = config_.bo;
    options.initial_samples = config_.random_samples;
    options.iterations = config_.iterations;
    options.threads = config_.threads;
    std::mutex mutex;
    std::vector<Finished> finished;
    size_t committed = 0;  // entries of `finished` whose ends are in known_ends_
    const BoundedObjective objective = [&](const Eigen::VectorXd& u, double /*incumbent*/) {
      bool converged = false;
      const Evaluation evaluation = Evaluate(stage, space.ToTransform(u), converged);
      const std::lock_guard<std::mutex> lock(mutex);
      finished.push_back({u, evaluation, converged});
      return evaluation.objective;
    };
    BayesOptHooks hooks;
    // Progress comes once a round is complete, so every run of a round sees
    // the same known ends, whatever the thread count.
    hooks.progress = [&](int done, int total, double best) {
      for (; committed < finished.size(); ++committed) {
        if (!finished[committed].converged) continue;
        known_ends_.push_back(finished[committed].evaluation.result);
        known_objectives_.push_back(finished[committed].evaluation.objective);
      }
      if (callbacks_.progress) callbacks_.progress({name, done, total, best});
    };
    hooks.stop_requested = callbacks_.stop_requested;
    if (short_stage) {
      hooks.enough = [&](const std::vector<BayesOptSample>& proposals) {
        return BestBasinConfirmed(proposals, finished);
      };
    }
    const size_t resumed = resume.size();
    hooks.resume = std::move(resume);
    std::vector<Eigen::VectorXd> starts = {Eigen::VectorXd::Constant(space.dimension(), 0.5)};
    starts.insert(starts.end(), extra_starts.begin(), extra_starts.end());
    BayesOptResult result = MinimiseBayesOpt(
        objective, space.Periodic(), options,
        config_.seed ^ (kStageSalt * static_cast<uint64_t>(stage + 1)), starts, hooks);
    AppendInProposalOrder(result.history, resumed, finished);
    return result;
  }

  const Evaluation& Best() const {
    return *std::min_element(
        history_.begin(), history_.end(),
        [](const Evaluation& a, const Evaluation& b) { return a.objective < b.objective; });
  }
  std::vector<Evaluation>& history() { return history_; }

 private:
  // The paper's objective: the error ICP reaches when started from T0. Runs
  // that reach the end of an earlier run take over its result. `converged`
  // tells whether the run found an end of its own.
  Evaluation Evaluate(int stage, const Transform& initial, bool& converged) const {
    const NearestNeighborIndex& target = pair_.prepared.search_target;
    Evaluation evaluation{stage, initial, initial, 0.0};
    converged = false;
    if (callbacks_.local_icp) {
      evaluation.result = callbacks_.local_icp(pair_.evaluation_source, target.points(), initial);
    } else {
      IcpOptions options = pair_.search_icp;
      const auto align = [&](const Points& source, const Transform& from) {
        return config_.icp_objective == IcpObjective::kPointToPlane
                   ? AlignPointToPlane(source, target, pair_.prepared.search_target_normals, from,
                                       options, known_ends_)
                   : AlignPointToPoint(source, target, from, options, known_ends_);
      };
      IcpResult icp;
      icp.transform = initial;
      if (pair_.coarse_source.size() < pair_.evaluation_source.size()) {
        icp = align(pair_.coarse_source, initial);
        options.max_iterations =
            std::max(options.max_iterations - icp.iterations, config_.finish_icp_iterations);
      }
      if (icp.joined_end < 0) icp = align(pair_.evaluation_source, icp.transform);
      evaluation.result = icp.transform;
      if (icp.joined_end >= 0) {
        evaluation.objective = known_objectives_[icp.joined_end];
        return evaluation;
      }
      converged = icp.converged;
    }
    evaluation.objective = ScoreAlignment(pair_.evaluation_source, target, evaluation.result,
                                          config_.EffectiveTruncation())
                               .truncated_mean;
    return evaluation;
  }

  // Evaluations of a round finish in any order; the history keeps the order
  // in which BO proposed them, so it does not depend on the thread count.
  // The first `resumed` proposals were recorded by the run that is resumed.
  void AppendInProposalOrder(const std::vector<BayesOptSample>& proposals, size_t resumed,
                             std::vector<Finished>& finished) {
    for (size_t k = resumed; k < proposals.size(); ++k) {
      const auto match = std::find_if(finished.begin(), finished.end(),
                                      [&](const Finished& e) { return e.x == proposals[k].x; });
      history_.push_back(match->evaluation);
      finished.erase(match);
    }
  }

  // True once kConfirmingRuns runs of the stage so far ended in the basin of
  // its best one. Read in proposal order, so ties and the answer do not
  // depend on the order in which runs finished.
  bool BestBasinConfirmed(const std::vector<BayesOptSample>& proposals,
                          const std::vector<Finished>& finished) const {
    if (static_cast<int>(proposals.size()) < kMinShortStageRuns) return false;
    std::vector<const Evaluation*> runs;
    for (const BayesOptSample& sample : proposals) {
      const auto match = std::find_if(finished.begin(), finished.end(),
                                      [&](const Finished& e) { return e.x == sample.x; });
      if (match != finished.end()) runs.push_back(&match->evaluation);
    }
    if (runs.empty()) return false;
    const Evaluation* best = *std::min_element(
        runs.begin(), runs.end(),
        [](const Evaluation* a, const Evaluation* b) { return a->objective < b->objective; });
    const auto confirming = std::count_if(runs.begin(), runs.end(), [&](const Evaluation* e) {
      return SameBasin(best->result, e->result, config_.voxel);
    });
    return confirming >= kConfirmingRuns;
  }

  const PairContext& pair_;
  const BoIcpConfig& config_;
  const RegistrationCallbacks& callbacks_;
  std::vector<Evaluation> history_;
  // Ends of the converged runs of finished rounds (all stages: they share the
  // ICP problem), and their objectives.
  std::vector<Transform> known_ends_;
  std::vector<double> known_objectives_;
};

// Unit coordinates of translation t in a translation-only search box, clamped
// into the box.
Eigen::VectorXd TranslationToUnit(const SearchSpace& space, const Eigen::Vector3d& t) {
  const Eigen::Vector3d offset = t - space.anchor.topRightCorner<3, 1>();
  Eigen::VectorXd u(space.dimension());
  for (int k = 0; k < space.dimension(); ++k) {
    const int p = space.parameters[k];
    u[k] = std::clamp(0.5 + offset[p - kX] / (2.0 * space.half_widths[p]), 0.0, 1.0);
  }
  return u;
}

// Where the search runs ended, one per basin, best search objective first,
// at most `count`.
std::vector<Transform> DistinctEnds(std::vector<Evaluation> history, int count, double voxel) {
  std::sort(history.begin(), history.end(),
            [](const Evaluation& a, const Evaluation& b) { return a.objective < b.objective; });
  std::vector<Transform> picked;
  for (const Evaluation& e : history) {
    if (static_cast<int>(picked.size()) >= count) break;
    const bool repeats = std::any_of(picked.begin(), picked.end(), [&](const Transform& p) {
      return SameBasin(p, e.result, voxel);
    });
    if (!repeats) picked.push_back(e.result);
  }
  return picked;
}

// Share of the first stage's runs (the ones that started from anywhere in
// the box) that ended in the basin of `answer`.
double BasinSupport(const std::vector<Evaluation>& history, const Transform& answer, double voxel) {
  int first_stage = 0, in_basin = 0;
  for (const Evaluation& e : history) {
    if (e.stage != 0) continue;
    ++first_stage;
    in_basin += SameBasin(answer, e.result, voxel) ? 1 : 0;
  }
  return first_stage > 0 ? static_cast<double>(in_basin) / first_stage : 0.0;
}

// Where a search's translation box lies: centred, for each rotation R, on
// pivot - R * source_centroid (the rotation turns the source about the pivot).
struct SearchBox {
  Point pivot = Point::Zero();
  Point source_centroid = Point::Zero();
  Eigen::Vector3d translation_bounds = Eigen::Vector3d::Zero();
};

// RegistrationResult::search_reach of `T` in `box`. An axis the search does
// not move along (bound 0) does not count.
double SearchReach(const SearchBox& box, const Transform& T) {
  const Point centre = box.pivot - T.topLeftCorner<3, 3>() * box.source_centroid;
  const Point offset = T.topRightCorner<3, 1>() - centre;
  double reach = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double bound = box.translation_bounds[axis];
    if (bound > 0.0) reach = std::max(reach, std::abs(offset[axis]) / bound);
  }
  return reach;
}

// Where a pair's searches are anchored: on the prior, or without one on "same
// orientation, centroids on top of each other"; rotations turn the source
// about the pivot, the anchor-mapped source centroid.
struct SearchFrame {
  Transform anchor = Transform::Identity();
  Point pivot = Point::Zero();
  Point source_centroid = Point::Zero();
};

SearchFrame MakeSearchFrame(const PreparedPair& prepared, const std::optional<Transform>& prior) {
  SearchFrame frame;
  frame.source_centroid = Centroid(prepared.search_source);
  frame.anchor = prior.value_or([&] {
    Transform centroids = Transform::Identity();
    centroids.topRightCorner<3, 1>() =
        Centroid(prepared.search_target.points()) - frame.source_centroid;
    return centroids;
  }());
  frame.pivot = frame.anchor.topLeftCorner<3, 3>() * frame.source_centroid +
                frame.anchor.topRightCorner<3, 1>();
  return frame;
}

PairContext MakePairContext(const PreparedPair& prepared, const BoIcpConfig& config) {
  Points evaluation_source = RandomSubsample(prepared.search_source, config.evaluation_points,
                                             config.seed ^ kSubsampleSalt);
  Points coarse_source =  // 0 points: all of them, so there is no separate first part
      RandomSubsample(evaluation_source, config.coarse_icp_points, config.seed ^ kCoarseSalt);
  return {prepared, std::move(evaluation_source), std::move(coarse_source),
          SearchIcpOptions(config)};
}

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

// The confidence features of the outcome's refined answer, and its overlap.
void Assess(SearchOutcome& out, const BoIcpConfig& config) {
  out.features.fitness = out.refined.score.fitness;
  out.features.rmse_ratio = out.refined.score.inlier_rmse / config.EffectiveInlierDistance();
  out.features.margin = out.refined.margin;
  out.features.resolution_deg = out.refined.resolution_deg;
  out.features.support = BasinSupport(out.history, out.refined.transform, config.voxel);
  out.features.probability_better = out.probability_better;
  out.confidence = Confidence(out.features);
  out.overlap = ScoreAlignment(out.prepared->search_source, out.prepared->search_target,
                               out.refined.transform, 1.5 * config.voxel, config.threads)
                    .fitness;
  // A rung without a search reports the search's objective at its answer.
  if (out.history.empty()) {
    out.objective =
        ScoreAlignment(out.prepared->search_source, out.prepared->search_target,
                       out.refined.transform, config.EffectiveTruncation(), config.threads)
            .truncated_mean;
  }
}

// Refines `starts` (best guess first) to the finest level, compares them
// there and assesses the winner.
void RefineAndAssess(SearchOutcome& out, const std::vector<Transform>& starts,
                     const BoIcpConfig& config, const RegistrationCallbacks& callbacks) {
  if (callbacks.progress) callbacks.progress({"refine", 0, 1, out.objective});
  out.refined = RefineCoarseToFine(starts, *out.prepared, config);
  if (callbacks.progress) callbacks.progress({"refine", 1, 1, out.objective});
  Assess(out, config);
}

// The `count` best distinct ends of the outcome's search, followed by the
// `learned` answers of earlier rungs that lie in none of their basins.
std::vector<Transform> EndsAndLearned(const SearchOutcome& out, int count, double voxel,
                                      const std::vector<Transform>& learned) {
  std::vector<Transform> starts = DistinctEnds(out.history, count, voxel);
  for (const Transform& T : learned) {
    const bool known = std::any_of(starts.begin(), starts.end(),
                                   [&](const Transform& p) { return SameBasin(p, T, voxel); });
    if (!known) starts.push_back(T);
  }
  return starts;
}

// Refines the `count` best distinct ends of the outcome's search, compares
// them at the finest level and assesses the winner.
void RefineEnds(SearchOutcome& out, int count, const BoIcpConfig& config,
                const RegistrationCallbacks& callbacks) {
  RefineAndAssess(out, DistinctEnds(out.history, count, config.voxel), config, callbacks);
}

// A new outcome of one prepared pair, before anything is refined.
SearchOutcome OutcomeOf(std::shared_ptr<const PreparedPair> prepared, const SearchFrame& frame,
                        const BoIcpConfig& config) {
  SearchOutcome out;
  out.box = {frame.pivot, frame.source_centroid, config.translation_bounds};
  out.source_points = prepared->search_source.size();
  out.target_points = prepared->search_target.size();
  out.prepared = std::move(prepared);
  return out;
}

// The nested or 6-DOF search of one pair: run whole, or run short (each stage
// ends once its best basin is confirmed) and later continued to the whole
// budget without repeating an evaluation.
class StagedSearch {
 public:
  StagedSearch(const PairContext& pair, const SearchFrame& frame, const BoIcpConfig& config,
               const RegistrationCallbacks& callbacks)
      : search_(pair, config, callbacks), frame_(frame), config_(config) {}

  // The first run (short or whole); `seeds` (T_target_source, earlier
  // answers) join the first stage's initial samples.
  void Start(bool short_budget, const std::vector<Transform>& seeds = {}) {
    const SearchSpace first = FirstSpace();
    for (const Transform& T : seeds) first_starts_.push_back(first.ToUnit(T));
    Run(short_budget);
  }

  // The rest of a short run, to the whole budget.
  void Continue() { Run(false); }

  // The search's best ends and the surrogate's view of them.
  void Report(SearchOutcome& out) {
    out.objective = search_.Best().objective;
    out.probability_better = probability_better_;
    out.gp_mean = last_->gp_mean_at_best;
    out.gp_std = last_->gp_std_at_best;
    out.history = search_.history();
  }

  int evaluations() { return static_cast<int>(search_.history().size()); }

 private:
  SearchSpace FirstSpace() const {
    const bool nested = config_.mode == SearchMode::kNested;
    return MakeSearchSpace(frame_.anchor, frame_.pivot, config_.rotation_bounds,
                           nested ? Eigen::Vector3d::Zero() : config_.translation_bounds);
  }

  void Run(bool short_budget) {
    const bool nested = config_.mode == SearchMode::kNested;
    first_ = search_.RunStage(0, FirstSpace(), nested ? "rotation" : "6dof", first_starts_,
                              short_budget, std::move(first_.history));
    probability_better_ = first_.probability_better;
    last_ = &first_;
    if (!nested) return;
    // The translation stage fixes the ICP-refined best rotation. Its box is
    // centred where that rotation about the pivot puts the source, not on the
    // ICP result: with partial overlap ICP may have slid far from the truth.
    // The ICP result itself is the second sample. The stage goes on from
    // where it ended only while its box stays where it was.
    const Transform rotated = search_.Best().result;
    std::vector<BayesOptSample> resume;
    if (second_from_ && *second_from_ == rotated) resume = std::move(second_.history);
    second_from_ = rotated;
    Transform centred = rotated;
    centred.topRightCorner<3, 1>() =
        frame_.pivot - rotated.topLeftCorner<3, 3>() * frame_.source_centroid;
    const SearchSpace translation =
        MakeSearchSpace(centred, frame_.pivot, Eigen::Vector3d::Zero(), config_.translation_bounds);
    second_ = search_.RunStage(1, translation, "translation",
                               {TranslationToUnit(translation, rotated.topRightCorner<3, 1>())},
                               short_budget, std::move(resume));
    probability_better_ = std::max(first_.probability_better, second_.probability_better);
    last_ = &second_;
  }

  Search search_;
  const SearchFrame frame_;
  const BoIcpConfig& config_;
  std::vector<Eigen::VectorXd> first_starts_;
  BayesOptResult first_, second_;
  std::optional<Transform> second_from_;  // the end the translation box was centred on
  const BayesOptResult* last_ = nullptr;
  double probability_better_ = 0.0;
};

SearchOutcome SearchAndRefine(const Points& source, const Points& target, const BoIcpConfig& config,
                              const std::optional<Transform>& prior,
                              const RegistrationCallbacks& callbacks) {
  const auto prepared = std::make_shared<const PreparedPair>(PreparePair(source, target, config));
  const PairContext pair = MakePairContext(*prepared, config);
  const SearchFrame frame = MakeSearchFrame(*prepared, prior);
  SearchOutcome out = OutcomeOf(prepared, frame, config);
  StagedSearch search(pair, frame, config, callbacks);
  search.Start(/*short_budget=*/false);
  search.Report(out);
  // The search objective is measured on coarse voxels; a few distinct ends
  // are refined and compared at the finest level.
  RefineEnds(out, config.refine_candidates, config, callbacks);
  return out;
}

// A doubtful answer may be a basin that only looked best on coarse voxels
// (a low-overlap view slid along a wall scores like the true one there),
// while the true one, visited by the same search, ranked below the few
// refined. The retry first compares this many of the search's distinct ends
// at the finest level.
constexpr int kWiderRefinementEnds = 8;

// The seed of a retry: another stream of the same job seed.
uint64_t RetrySeed(uint64_t seed) { return seed ^ 0xa0761d6478bd642fULL; }

// The retry of a doubtful search: in 6 DOF, with another seed, and at
// config.retry_voxel when set. The finest refinement level stays, so both
// answers' fitness is measured alike.
BoIcpConfig RetryConfig(const BoIcpConfig& config) {
  BoIcpConfig retry = config;
  retry.mode = SearchMode::kSixDof;
  retry.seed = RetrySeed(config.seed);
  if (config.retry_voxel > 0.0) {
    const double scale = config.retry_voxel / config.voxel;
    retry.refine_voxel = config.EffectiveRefineVoxel();
    retry.objective_truncation = config.EffectiveTruncation() * scale;
    retry.max_correspondence_distance = config.EffectiveMaxCorrespondence() * scale;
    retry.voxel = config.retry_voxel;
  }
  return retry;
}

// What a registration kept, and every attempt it made.
struct Registered {
  SearchOutcome kept;
  Rung rung = Rung::kFullSearch;
  std::vector<Attempt> attempts;
};

double SecondsSince(std::chrono::steady_clock::time_point started) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

Attempt AttemptOf(AttemptKind kind, const BoIcpConfig& config, const SearchOutcome& outcome,
                  int evaluations, int refined_ends,
                  std::chrono::steady_clock::time_point started) {
  return {kind,
          config.mode,
          config.seed,
          outcome.refined.score.fitness,
          outcome.confidence,
          evaluations,
          refined_ends,
          SecondsSince(started),
          false,
          outcome.refined.transform,
          outcome.features};
}

// Budget::kFixed: the paper's search, then for a doubtful answer a wider
// refinement and a 6-DOF search; the better fit at the finest level is kept.
Registered RegisterFixed(const Points& source, const Points& target, const BoIcpConfig& config,
                         const std::optional<Transform>& prior,
                         const RegistrationCallbacks& callbacks) {
  Registered out;
  const auto search = [&](const BoIcpConfig& attempt_config) {
    const auto started = std::chrono::steady_clock::now();
    SearchOutcome outcome = SearchAndRefine(source, target, attempt_config, prior, callbacks);
    out.attempts.push_back(AttemptOf(AttemptKind::kSearch, attempt_config, outcome,
                                     static_cast<int>(outcome.history.size()),
                                     attempt_config.refine_candidates, started));
    return outcome;
  };
  out.kept = search(config);
  size_t kept_index = 0;
  const auto keep_if_better = [&](SearchOutcome&& candidate) {
    if (candidate.refined.score.fitness <= out.kept.refined.score.fitness) return;
    out.kept = std::move(candidate);
    kept_index = out.attempts.size() - 1;
  };
  if (config.retry_when_doubtful && out.kept.confidence < kDoubtfulBelow) {
    const auto started = std::chrono::steady_clock::now();
    SearchOutcome wider = out.kept;
    RefineEnds(wider, kWiderRefinementEnds, config, callbacks);
    out.attempts.push_back(
        AttemptOf(AttemptKind::kWiderRefinement, config, wider, 0, kWiderRefinementEnds, started));
    keep_if_better(std::move(wider));
  }
  if (config.retry_when_doubtful && out.kept.confidence < kDoubtfulBelow)
    keep_if_better(search(RetryConfig(config)));
  out.attempts[kept_index].kept = true;
  out.rung = kept_index == 0 ? Rung::kFullSearch : Rung::kRetry;
  return out;
}

// Starts around a guess that look for a competing basin next to it: the
// guess turned both ways about the vertical through the pivot by a quarter
// turn (or the yaw bound, when smaller), and moved both ways along the
// translation axis with the widest bound by half that bound.
std::vector<Transform> ProbesAround(const Transform& guess, const Point& source_centroid,
                                    const BoIcpConfig& config) {
  const Point pivot = guess.topLeftCorner<3, 3>() * source_centroid + guess.topRightCorner<3, 1>();
  const double turn = std::min(M_PI / 4, config.rotation_bounds[2]);
  Eigen::Index axis = 0;
  config.translation_bounds.maxCoeff(&axis);
  const Eigen::Vector3d shift = Eigen::Vector3d::Unit(axis) * 0.5 * config.translation_bounds[axis];
  std::vector<Transform> probes;
  for (const double sign : {1.0, -1.0}) {
    if (turn > 0.0) {
      Transform turned = Transform::Identity();
      const Eigen::Matrix3d R = RotationFromEuler(0.0, 0.0, sign * turn);
      turned.topLeftCorner<3, 3>() = R;
      turned.topRightCorner<3, 1>() = pivot - R * pivot;
      probes.push_back(turned * guess);
    }
    if (shift.norm() > 0.0) {
      Transform moved = guess;
      moved.topRightCorner<3, 1>() += sign * shift;
      probes.push_back(moved);
    }
  }
  return probes;
}

// Feature hypotheses of the search clouds: FPFH (normals within 3 voxels,
// features within 5) matched and solved by RANSAC over the correspondences,
// a few distinct ones, most inliers first. The clouds are first thinned to
// about kFeaturePoints points (a surface's points fall with the square of
// the voxel): matching costs the product of the two clouds' sizes, and
// hypotheses need only land in ICP's basin.
constexpr size_t kFeaturePoints = 4000;

std::vector<Transform> FeatureGuesses(const PreparedPair& prepared, const BoIcpConfig& config) {
  const size_t points = std::max(prepared.search_source.size(), prepared.search_target.size());
  const double voxel =
      config.voxel *
      std::sqrt(std::max(1.0, static_cast<double>(points) / static_cast<double>(kFeaturePoints)));
  const NearestNeighborIndex source(VoxelDownsample(prepared.search_source, voxel));
  const NearestNeighborIndex target(VoxelDownsample(prepared.search_target.points(), voxel));
  const Points source_normals = EstimateSurfaceNormals(source, 3.0 * voxel, config.threads);
  const Points target_normals = EstimateSurfaceNormals(target, 3.0 * voxel, config.threads);
  const FpfhFeatures source_features =
      ComputeFpfhFeatures(source, source_normals, 5.0 * voxel, config.threads);
  const FpfhFeatures target_features =
      ComputeFpfhFeatures(target, target_normals, 5.0 * voxel, config.threads);
  FeatureMatchOptions options;
  options.inlier_distance = 1.5 * voxel;
  options.distinct_translation = 3.0 * voxel;
  options.seed = config.seed ^ kFeatureSalt;
  options.threads = config.threads;
  std::vector<Transform> guesses;
  for (const FeatureHypothesis& h : FeatureHypotheses(source.points(), source_features,
                                                      target.points(), target_features, options)) {
    guesses.push_back(h.transform);
  }
  return guesses;
}

// Budget::kAuto: the escalation ladder. Each rung runs only while every
// answer so far is doubtful, and hands what it learned (its answer, its
// hypotheses) to the next as starts; the most confident answer is kept. The
// rungs share one prepared pair, so their answers are compared on the same
// finest points.
class Ladder {
 public:
  Ladder(const Points& source, const Points& target, const BoIcpConfig& config,
         const std::optional<Transform>& prior, const RegistrationCallbacks& callbacks)
      : source_(source),
        target_(target),
        config_(config),
        prior_(prior),
        callbacks_(callbacks),
        prepared_(std::make_shared<const PreparedPair>(PreparePair(source, target, config))),
        frame_(MakeSearchFrame(*prepared_, prior)) {}

  Registered Run(const std::optional<Transform>& guess) {
    if (const std::optional<Transform> start = prior_ ? prior_ : guess) {
      if (PriorRung(*start)) return Finish();
    }
    if (FeatureRung()) return Finish();
    const PairContext pair = MakePairContext(*prepared_, config_);
    StagedSearch search(pair, frame_, config_, callbacks_);
    if (SearchRung(search, /*short_budget=*/true)) return Finish();
    if (SearchRung(search, /*short_budget=*/false)) return Finish();
    if (config_.retry_when_doubtful) RetryRung();
    return Finish();
  }

 private:
  // The refinement from the prior (or guess), beside probes that look for a
  // competing basin next to it.
  bool PriorRung(const Transform& start) {
    const auto started = std::chrono::steady_clock::now();
    std::vector<Transform> starts = {start};
    for (const Transform& probe : ProbesAround(start, frame_.source_centroid, config_))
      starts.push_back(probe);
    SearchOutcome out = OutcomeOf(prepared_, frame_, config_);
    RefineAndAssess(out, starts, config_, callbacks_);
    learned_.push_back(out.refined.transform);
    const auto runs = static_cast<int>(starts.size());
    const Attempt attempt = AttemptOf(AttemptKind::kPrior, config_, out, runs, runs, started);
    return Consider(std::move(out), Rung::kPrior, attempt);
  }

  // Feature hypotheses refined beside every answer learned so far.
  bool FeatureRung() {
    const auto started = std::chrono::steady_clock::now();
    if (callbacks_.stop_requested && callbacks_.stop_requested()) throw Cancelled();
    std::vector<Transform> starts = FeatureGuesses(*prepared_, config_);
    const size_t hypotheses = starts.size();
    starts.insert(starts.end(), learned_.begin(), learned_.end());
    if (starts.empty()) return false;
    SearchOutcome out = OutcomeOf(prepared_, frame_, config_);
    RefineAndAssess(out, starts, config_, callbacks_);
    learned_.insert(learned_.begin(), starts.begin(),
                    starts.begin() + static_cast<std::ptrdiff_t>(hypotheses));
    learned_.push_back(out.refined.transform);
    const Attempt attempt =
        AttemptOf(AttemptKind::kFeatures, config_, out, static_cast<int>(hypotheses),
                  static_cast<int>(starts.size()), started);
    return Consider(std::move(out), Rung::kFeatures, attempt);
  }

  // The search, short or continued to its whole budget, seeded with the
  // answers learned so far; its distinct ends are refined beside them.
  bool SearchRung(StagedSearch& search, bool short_budget) {
    const auto started = std::chrono::steady_clock::now();
    const int before = search.evaluations();
    if (short_budget) {
      search.Start(true, learned_);
    } else {
      search.Continue();
    }
    SearchOutcome out = OutcomeOf(prepared_, frame_, config_);
    search.Report(out);
    const int ends = short_budget ? config_.refine_candidates : kWiderRefinementEnds;
    const std::vector<Transform> starts = EndsAndLearned(out, ends, config_.voxel, learned_);
    RefineAndAssess(out, starts, config_, callbacks_);
    const Attempt attempt =
        AttemptOf(short_budget ? AttemptKind::kShortSearch : AttemptKind::kSearch, config_, out,
                  search.evaluations() - before, static_cast<int>(starts.size()), started);
    learned_.push_back(out.refined.transform);
    return Consider(std::move(out), short_budget ? Rung::kShortSearch : Rung::kFullSearch, attempt);
  }

  // A 6-DOF search with another seed and the budget of a whole nested search
  // (both stages' samples and steps), seeded with what the rungs before it
  // learned. Its finest points are the other rungs', so the confidences
  // compare like with like.
  void RetryRung() {
    const auto started = std::chrono::steady_clock::now();
    BoIcpConfig retry = RetryConfig(config_);
    if (config_.mode == SearchMode::kNested) {
      retry.random_samples *= 2;
      retry.iterations *= 2;
    }
    const auto prepared =
        std::make_shared<const PreparedPair>(PreparePair(source_, target_, retry, config_.seed));
    const PairContext pair = MakePairContext(*prepared, retry);
    const SearchFrame frame = MakeSearchFrame(*prepared, prior_);
    StagedSearch search(pair, frame, retry, callbacks_);
    search.Start(false, learned_);
    SearchOutcome out = OutcomeOf(prepared, frame, retry);
    search.Report(out);
    const std::vector<Transform> starts =
        EndsAndLearned(out, kWiderRefinementEnds, retry.voxel, {kept_.refined.transform});
    RefineAndAssess(out, starts, retry, callbacks_);
    const Attempt attempt = AttemptOf(AttemptKind::kSearch, retry, out, search.evaluations(),
                                      static_cast<int>(starts.size()), started);
    Consider(std::move(out), Rung::kRetry, attempt);
  }

  // Keeps `out` when it is the most confident answer so far; true once the
  // kept answer is trusted.
  bool Consider(SearchOutcome&& out, Rung rung, Attempt attempt) {
    if (attempts_.empty() || out.confidence > kept_.confidence) {
      kept_ = std::move(out);
      rung_ = rung;
      kept_index_ = attempts_.size();
    }
    attempts_.push_back(attempt);
    return kept_.confidence >= kDoubtfulBelow;
  }

  Registered Finish() {
    attempts_[kept_index_].kept = true;
    return {std::move(kept_), rung_, std::move(attempts_)};
  }

  const Points& source_;
  const Points& target_;
  const BoIcpConfig& config_;
  const std::optional<Transform>& prior_;
  const RegistrationCallbacks& callbacks_;
  std::shared_ptr<const PreparedPair> prepared_;
  SearchFrame frame_;
  std::vector<Transform> learned_;  // answers and hypotheses of the rungs so far, to seed the next
  SearchOutcome kept_;
  Rung rung_ = Rung::kFullSearch;
  std::vector<Attempt> attempts_;
  size_t kept_index_ = 0;
};

}  // namespace

std::string RungName(Rung rung) {
  switch (rung) {
    case Rung::kPrior:
      return "prior";
    case Rung::kFeatures:
      return "features";
    case Rung::kShortSearch:
      return "short-search";
    case Rung::kFullSearch:
      return "full-search";
    case Rung::kRetry:
      return "retry";
  }
  return "full-search";
}

std::string AttemptKindName(AttemptKind kind) {
  switch (kind) {
    case AttemptKind::kPrior:
      return "prior";
    case AttemptKind::kFeatures:
      return "features";
    case AttemptKind::kShortSearch:
      return "short-search";
    case AttemptKind::kSearch:
      return "search";
    case AttemptKind::kWiderRefinement:
      return "wider-refinement";
  }
  return "search";
}

RegistrationResult RegisterPair(const Points& source, const Points& target,
                                const BoIcpConfig& requested, const std::optional<Transform>& prior,
                                const RegistrationCallbacks& callbacks,
                                const std::optional<Transform>& guess) {
  const auto started = std::chrono::steady_clock::now();
  BoIcpConfig config = requested;
  std::vector<std::string> auto_fields;
  if (!config.automatic.empty()) {
    auto_fields =
        ApplyChosenSettings(ChooseSettingsForClouds({&source, &target}, CloudFormat::kAuto,
                                                    config.seed, 2, config.threads),
                            config);
  }
  ValidateConfig(config);

  Registered registered = config.budget == Budget::kFixed
                              ? RegisterFixed(source, target, config, prior, callbacks)
                              : Ladder(source, target, config, prior, callbacks).Run(guess);
  SearchOutcome& kept = registered.kept;
  RegistrationResult result;
  result.transform = kept.refined.transform;
  result.objective = kept.objective;
  result.fitness = kept.refined.score.fitness;
  result.inlier_rmse = kept.refined.score.inlier_rmse;
  const PyramidLevel& finest = kept.prepared->pyramid.back();
  result.information = PairInformation(finest.source, finest.target, result.transform,
                                       config.EffectiveInlierDistance());
  result.overlap = kept.overlap;
  result.search_reach = SearchReach(kept.box, result.transform);
  result.probability_better = kept.probability_better;
  result.features = kept.features;
  result.confidence = kept.confidence;
  result.doubtful = result.confidence < kDoubtfulBelow;
  result.gp_mean = kept.gp_mean;
  result.gp_std = kept.gp_std;
  result.answered_by = registered.rung;
  for (const Attempt& attempt : registered.attempts) result.evaluations += attempt.evaluations;
  result.source_points = kept.source_points;
  result.target_points = kept.target_points;
  result.history = std::move(kept.history);
  result.attempts = std::move(registered.attempts);
  result.config = config;
  result.auto_fields = std::move(auto_fields);
  result.runtime_s = SecondsSince(started);
  return result;
}

}  // namespace boicp
