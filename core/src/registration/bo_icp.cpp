
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
#include "boicp/registration/icp.hpp"
#include "boicp/registration/nearest_neighbors.hpp"
#include "boicp/registration/preprocess.hpp"
#include "boicp/registration/refinement.hpp"
#include "boicp/registration/search_space.hpp"

namespace boicp {
namespace {

// Distinct seeds for the independent random choices of one registration.
constexpr uint64_t kSubsampleSalt = 0x9e3779b97f4a7c15ULL;
constexpr uint64_t kStageSalt = 0xbf58476d1ce4e5b9ULL;
constexpr uint64_t kCoarseSalt = 0x94d049bb133111ebULL;

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
  // sample, followed by `extra_starts` (unit coordinates).
  BayesOptResult RunStage(int stage, const SearchSpace& space, const std::string& name,
                          const std::vector<Eigen::VectorXd>& extra_starts = {}) {
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
    // Progress comes once a round is complete, so every run of a round sees
    // the same known ends, whatever the thread count.
    const BayesOptProgress progress = [&](int done, int total, double best) {
      for (; committed < finished.size(); ++committed) {
        if (!finished[committed].converged) continue;
        known_ends_.push_back(finished[committed].evaluation.result);
        known_objectives_.push_back(finished[committed].evaluation.objective);
      }
      if (callbacks_.progress) callbacks_.progress({name, done, total, best});
    };
    std::vector<Eigen::VectorXd> starts = {Eigen::VectorXd::Constant(space.dimension(), 0.5)};
    starts.insert(starts.end(), extra_starts.begin(), extra_starts.end());
    BayesOptResult result =
        MinimiseBayesOpt(objective, space.Periodic(), options,
                         config_.seed ^ (kStageSalt * static_cast<uint64_t>(stage + 1)), starts,
                         progress, callbacks_.stop_requested);
    AppendInProposalOrder(result.history, finished);
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
  void AppendInProposalOrder(const std::vector<BayesOptSample>& proposals,
                             std::vector<Finished>& finished) {
    for (const BayesOptSample& sample : proposals) {
      const auto match = std::find_if(finished.begin(), finished.end(),
                                      [&](const Finished& entry) { return entry.x == sample.x; });
      history_.push_back(match->evaluation);
      finished.erase(match);
    }
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

bool SameBasin(const Transform& a, const Transform& b, double voxel) {
  const Transform delta = a.inverse() * b;
  return RotationAngle(delta) < 5.0 * M_PI / 180.0 && TranslationNorm(delta) < 3.0 * voxel;
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

// One search (nested or 6 DOF) and the refinement of its distinct best ends.
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

// Refines the `count` best distinct ends of the outcome's search, compares
// them at the finest level and assesses the winner.
void RefineEnds(SearchOutcome& out, int count, const BoIcpConfig& config,
                const RegistrationCallbacks& callbacks) {
  if (callbacks.progress) callbacks.progress({"refine", 0, 1, out.objective});
  out.refined =
      RefineCoarseToFine(DistinctEnds(out.history, count, config.voxel), *out.prepared, config);
  if (callbacks.progress) callbacks.progress({"refine", 1, 1, out.objective});
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
}

SearchOutcome SearchAndRefine(const Points& source, const Points& target, const BoIcpConfig& config,
                              const std::optional<Transform>& prior,
                              const RegistrationCallbacks& callbacks) {
  const auto prepared_pair =
      std::make_shared<const PreparedPair>(PreparePair(source, target, config));
  const PreparedPair& prepared = *prepared_pair;
  Points evaluation_source = RandomSubsample(prepared.search_source, config.evaluation_points,
                                             config.seed ^ kSubsampleSalt);
  Points coarse_source =  // 0 points: all of them, so there is no separate first part
      RandomSubsample(evaluation_source, config.coarse_icp_points, config.seed ^ kCoarseSalt);
  const PairContext pair{prepared, std::move(evaluation_source), std::move(coarse_source),
                         SearchIcpOptions(config)};
  const Points& search_source = prepared.search_source;
  const Point source_centroid = Centroid(search_source);

  // Without a prior the box is centred on "same orientation, centroids on top
  // of each other"; with one, on the prior itself.
  const Transform anchor = prior.value_or([&] {
    Transform centroids = Transform::Identity();
    centroids.topRightCorner<3, 1>() = Centroid(prepared.search_target.points()) - source_centroid;
    return centroids;
  }());
  const Point pivot =
      anchor.topLeftCorner<3, 3>() * source_centroid + anchor.topRightCorner<3, 1>();

  Search search(pair, config, callbacks);
  SearchOutcome out;
  out.prepared = prepared_pair;
  out.box = {pivot, source_centroid, config.translation_bounds};
  BayesOptResult last;
  if (config.mode == SearchMode::kNested) {
    const BayesOptResult rotation = search.RunStage(
        0, MakeSearchSpace(anchor, pivot, config.rotation_bounds, Eigen::Vector3d::Zero()),
        "rotation");
    // The translation stage fixes the ICP-refined best rotation. Its box is
    // centred where that rotation about the pivot puts the source, not on the
    // ICP result: with partial overlap ICP may have slid far from the truth.
    // The ICP result itself is the second sample.
    const Transform rotated = search.Best().result;
    Transform centred = rotated;
    centred.topRightCorner<3, 1>() = pivot - rotated.topLeftCorner<3, 3>() * source_centroid;
    const SearchSpace translation =
        MakeSearchSpace(centred, pivot, Eigen::Vector3d::Zero(), config.translation_bounds);
    last = search.RunStage(1, translation, "translation",
                           {TranslationToUnit(translation, rotated.topRightCorner<3, 1>())});
    out.probability_better = std::max(rotation.probability_better, last.probability_better);
  } else {
    last = search.RunStage(
        0, MakeSearchSpace(anchor, pivot, config.rotation_bounds, config.translation_bounds),
        "6dof");
    out.probability_better = last.probability_better;
  }
  out.objective = search.Best().objective;

  out.gp_mean = last.gp_mean_at_best;
  out.gp_std = last.gp_std_at_best;
  out.history = std::move(search.history());
  out.source_points = search_source.size();
  out.target_points = prepared.search_target.size();
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

}  // namespace

std::string AttemptKindName(AttemptKind kind) {
  return kind == AttemptKind::kSearch ? "search" : "wider-refinement";
}

RegistrationResult RegisterPair(const Points& source, const Points& target,
                                const BoIcpConfig& requested, const std::optional<Transform>& prior,
                                const RegistrationCallbacks& callbacks) {
  const auto started = std::chrono::steady_clock::now();
  BoIcpConfig config = requested;
  std::vector<std::string> auto_fields;
  if (!config.automatic.empty()) {
    auto_fields = ApplyChosenSettings(
        ChooseSettingsForClouds({&source, &target}, CloudFormat::kAuto, config.seed), config);
  }
  ValidateConfig(config);

  RegistrationResult result;
  const auto record = [&](AttemptKind kind, const BoIcpConfig& attempt_config,
                          const SearchOutcome& outcome, int refined_ends,
                          std::chrono::steady_clock::time_point attempt_started) {
    result.attempts.push_back(
        {kind, attempt_config.mode, attempt_config.seed, outcome.refined.score.fitness,
         outcome.confidence,
         kind == AttemptKind::kSearch ? static_cast<int>(outcome.history.size()) : 0, refined_ends,
         std::chrono::duration<double>(std::chrono::steady_clock::now() - attempt_started).count(),
         false});
  };
  const auto search = [&](const BoIcpConfig& attempt_config) {
    const auto attempt_started = std::chrono::steady_clock::now();
    SearchOutcome outcome = SearchAndRefine(source, target, attempt_config, prior, callbacks);
    record(AttemptKind::kSearch, attempt_config, outcome, attempt_config.refine_candidates,
           attempt_started);
    return outcome;
  };
  SearchOutcome kept = search(config);
  size_t kept_index = 0;
  const auto keep_if_better = [&](SearchOutcome&& candidate) {
    if (candidate.refined.score.fitness <= kept.refined.score.fitness) return;
    kept = std::move(candidate);
    kept_index = result.attempts.size() - 1;
  };
  if (config.retry_when_doubtful && kept.confidence < kDoubtfulBelow) {
    const auto attempt_started = std::chrono::steady_clock::now();
    SearchOutcome wider = kept;
    RefineEnds(wider, kWiderRefinementEnds, config, callbacks);
    record(AttemptKind::kWiderRefinement, config, wider, kWiderRefinementEnds, attempt_started);
    keep_if_better(std::move(wider));
  }
  if (config.retry_when_doubtful && kept.confidence < kDoubtfulBelow)
    keep_if_better(search(RetryConfig(config)));
  result.attempts[kept_index].kept = true;

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
  result.evaluations = static_cast<int>(kept.history.size());
  result.source_points = kept.source_points;
  result.target_points = kept.target_points;
  result.history = std::move(kept.history);
  result.config = config;
  result.auto_fields = std::move(auto_fields);
  result.runtime_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace boicp
