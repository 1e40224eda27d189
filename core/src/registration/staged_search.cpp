#include "staged_search.hpp"

#include <algorithm>
#include <mutex>
#include <utility>

#include "boicp/icp/alignment_score.hpp"
#include "boicp/icp/free_space.hpp"
#include "boicp/icp/icp.hpp"
#include "boicp/icp/preprocess.hpp"

namespace boicp {
namespace {

// Distinct seeds for the independent random choices of one registration.
constexpr uint64_t kSubsampleSalt = 0x9e3779b97f4a7c15ULL;
constexpr uint64_t kStageSalt = 0xbf58476d1ce4e5b9ULL;
constexpr uint64_t kCoarseSalt = 0x94d049bb133111ebULL;

// A short search stage ends once this many of its runs, out of at least
// kMinShortStageRuns, ended in its best basin: ICP from that many starts
// agrees on it.
constexpr int kConfirmingRuns = 5;
constexpr int kMinShortStageRuns = 10;

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

// SeenThroughShare of the finest source points, from the target sensor at
// its frame's origin (-target_centre among the centred points), beyond 3
// finest voxels. A view of fewer than kViewCells cells (about 13 by 13
// degrees) is not a sensor's: the scan's origin is elsewhere.
constexpr size_t kViewCells = 200;

double SeenThrough(const PreparedPair& pair, const Transform& centred, const BoIcpConfig& config) {
  const bool pyramid = !pair.pyramid.empty();
  const Points& source = pyramid ? pair.pyramid.back().source : pair.search_source;
  const NearestNeighborIndex& target = pyramid ? pair.pyramid.back().target : pair.search_target;
  const double voxel = pyramid ? pair.pyramid.back().voxel : config.voxel;
  const RangeImage view(target.points(), -pair.target_centre);
  if (view.covered_cells() < kViewCells) return 0.0;
  return SeenThroughShare(source, target, view, centred, 3.0 * voxel,
                          config.EffectiveInlierDistance());
}

// The confidence features of the outcome's refined answer, and its overlap.
void Assess(SearchOutcome& out, const BoIcpConfig& config) {
  out.features.fitness = out.refined.score.fitness;
  out.features.rmse_ratio = out.refined.score.inlier_rmse / config.EffectiveInlierDistance();
  out.features.margin = out.refined.margin;
  out.features.margin_measured = out.refined.margin_measured;
  out.features.resolution_deg = out.refined.resolution_deg;
  out.features.support = BasinSupport(out.history, out.refined.transform, config.voxel);
  out.features.probability_better = out.probability_better;
  out.features.seen_through = SeenThrough(*out.prepared, out.refined.transform, config);
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

// The seed of a retry: another stream of the same job seed.
uint64_t RetrySeed(uint64_t seed) { return seed ^ 0xa0761d6478bd642fULL; }

}  // namespace

// Two ICP ends in one basin: within 5 degrees and 3 search voxels.
bool SameBasin(const Transform& a, const Transform& b, double voxel) {
  const Transform delta = a.inverse() * b;
  return RotationAngle(delta) < 5.0 * M_PI / 180.0 && TranslationNorm(delta) < 3.0 * voxel;
}

class SearchStages {
  struct Finished {
    Eigen::VectorXd x;
    Evaluation evaluation;
    bool converged;  // its end may be joined by later runs
  };

 public:
  SearchStages(const PairContext& pair, const BoIcpConfig& config,
               const RegistrationCallbacks& callbacks)
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
        objective, space.Inputs(), options,
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

StagedSearch::StagedSearch(const PairContext& pair, const SearchFrame& frame,
                           const BoIcpConfig& config, const RegistrationCallbacks& callbacks)
    : search_(std::make_unique<SearchStages>(pair, config, callbacks)),
      frame_(frame),
      config_(config) {}

StagedSearch::~StagedSearch() = default;

void StagedSearch::Start(bool short_budget, const std::vector<Transform>& seeds) {
  const SearchSpace first = FirstSpace();
  for (const Transform& T : seeds) first_starts_.push_back(first.ToUnit(T));
  Run(short_budget);
}

void StagedSearch::Report(SearchOutcome& out) const {
  out.objective = search_->Best().objective;
  out.probability_better = probability_better_;
  out.gp_mean = last_->gp_mean_at_best;
  out.gp_std = last_->gp_std_at_best;
  out.history = search_->history();
}

int StagedSearch::evaluations() const { return static_cast<int>(search_->history().size()); }

SearchSpace StagedSearch::FirstSpace() const {
  const bool nested = config_.mode == SearchMode::kNested;
  return MakeSearchSpace(frame_.anchor, frame_.pivot, config_.rotation_bounds,
                         nested ? Eigen::Vector3d::Zero() : config_.translation_bounds,
                         config_.EffectiveRotationCoordinates());
}

void StagedSearch::Run(bool short_budget) {
  const bool nested = config_.mode == SearchMode::kNested;
  first_ = search_->RunStage(0, FirstSpace(), nested ? "rotation" : "6dof", first_starts_,
                             short_budget, std::move(first_.history));
  probability_better_ = first_.probability_better;
  last_ = &first_;
  if (!nested) return;
  // The translation stage fixes the ICP-refined best rotation. Its box is
  // centred where that rotation about the pivot puts the source, not on the
  // ICP result: with partial overlap ICP may have slid far from the truth.
  // The ICP result itself is the second sample. The stage goes on from
  // where it ended only while its box stays where it was.
  const Transform rotated = search_->Best().result;
  std::vector<BayesOptSample> resume;
  if (second_from_ && *second_from_ == rotated) resume = std::move(second_.history);
  second_from_ = rotated;
  Transform centred = rotated;
  centred.topRightCorner<3, 1>() =
      frame_.pivot - rotated.topLeftCorner<3, 3>() * frame_.source_centroid;
  const SearchSpace translation =
      MakeSearchSpace(centred, frame_.pivot, Eigen::Vector3d::Zero(), config_.translation_bounds);
  second_ = search_->RunStage(1, translation, "translation",
                              {TranslationToUnit(translation, rotated.topRightCorner<3, 1>())},
                              short_budget, std::move(resume));
  probability_better_ = std::max(first_.probability_better, second_.probability_better);
  last_ = &second_;
}

SearchOutcome SearchAndRefine(const ScanPyramid& source, const ScanPyramid& target,
                              const BoIcpConfig& config, const std::optional<Transform>& prior,
                              const RegistrationCallbacks& callbacks,
                              std::optional<uint64_t> level_seed) {
  const auto prepared =
      std::make_shared<const PreparedPair>(PreparePair(source, target, config, level_seed));
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

}  // namespace boicp
