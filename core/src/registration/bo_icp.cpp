
#include "boicp/registration/bo_icp.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <utility>

#include "boicp/icp/preprocess.hpp"
#include "boicp/icp/slide_rival.hpp"
#include "boicp/icp/unconstrained_slides.hpp"
#include "boicp/registration/auto_settings.hpp"
#include "boicp/registration/confidence.hpp"
#include "boicp/registration/feature_hypotheses.hpp"
#include "boicp/registration/refinement.hpp"
#include "boicp/registration/scan_features.hpp"
#include "boicp/registration/search_space.hpp"
#include "boicp/util/elapsed.hpp"
#include "staged_search.hpp"

namespace boicp {
namespace {

constexpr uint64_t kFeatureSalt = 0xd1b54a32d192ed03ULL;

// What a registration kept, and every attempt it made.
struct Registered {
  SearchOutcome kept;
  Rung rung = Rung::kFullSearch;
  std::vector<Attempt> attempts;
};

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
Registered RegisterFixed(const ScanPyramid& source, const ScanPyramid& target,
                         const BoIcpConfig& config, const std::optional<Transform>& prior,
                         const RegistrationCallbacks& callbacks) {
  Registered out;
  const auto search = [&](const BoIcpConfig& attempt_config) {
    const auto started = std::chrono::steady_clock::now();
    SearchOutcome outcome =
        SearchAndRefine(source, target, attempt_config, prior, callbacks, config.seed);
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
  if (config.retry_when_doubtful && out.kept.confidence < kTrustedFrom) {
    const auto started = std::chrono::steady_clock::now();
    SearchOutcome wider = out.kept;
    RefineEnds(wider, kWiderRefinementEnds, config, callbacks);
    out.attempts.push_back(
        AttemptOf(AttemptKind::kWiderRefinement, config, wider, 0, kWiderRefinementEnds, started));
    keep_if_better(std::move(wider));
  }
  if (config.retry_when_doubtful && out.kept.confidence < kTrustedFrom)
    keep_if_better(search(RetryConfig(config)));
  out.attempts[kept_index].kept = true;
  out.rung = kept_index == 0 ? Rung::kFullSearch : Rung::kRetry;
  return out;
}

// Starts around a guess that look for a competing basin next to it: the
// guess turned both ways about the vertical through the pivot by a quarter
// turn (or the yaw bound, when smaller), and moved both ways by half the
// bound along every translation axis whose bound is at least half the
// widest. A guess short of the motion along the direction of travel (which
// a scan's axes do not tell) otherwise ends where ICP stalls on the way.
std::vector<Transform> ProbesAround(const Transform& guess, const Point& source_centroid,
                                    const BoIcpConfig& config) {
  const Point pivot = guess.topLeftCorner<3, 3>() * source_centroid + guess.topRightCorner<3, 1>();
  const double turn = std::min(M_PI / 4, config.rotation_bounds[2]);
  const double widest = config.translation_bounds.maxCoeff();
  std::vector<Transform> probes;
  for (const double sign : {1.0, -1.0}) {
    if (turn > 0.0) {
      Transform turned = Transform::Identity();
      const Eigen::Matrix3d R = RotationFromEuler(0.0, 0.0, sign * turn);
      turned.topLeftCorner<3, 3>() = R;
      turned.topRightCorner<3, 1>() = pivot - R * pivot;
      probes.push_back(turned * guess);
    }
    for (int axis = 0; axis < 3; ++axis) {
      const double bound = config.translation_bounds[axis];
      if (bound <= 0.0 || bound < 0.5 * widest) continue;
      Transform moved = guess;
      moved(axis, 3) += sign * 0.5 * bound;
      probes.push_back(moved);
    }
  }
  return probes;
}

// A scan's features at `step` from its search level: the pyramid's own,
// computed once for every pair, when the pyramid was built at this search
// voxel. Its sensor stood at the scan frame's origin, -centre in the
// centred search level.
std::shared_ptr<const ScanFeatures> FeaturesOf(const ScanPyramid& scan, const Points& search_level,
                                               int step, const BoIcpConfig& config) {
  const Point sensor = -scan.centre;
  if (!scan.voxels.empty() && scan.voxels[0] == config.voxel) {
    return scan.features->At(search_level, config.voxel, step, config.threads, sensor);
  }
  return std::make_shared<const ScanFeatures>(
      ComputeScanFeatures(search_level, config.voxel, step, config.threads, sensor));
}

// Feature hypotheses of the search clouds: both scans' FPFH at the coarser
// of their feature steps, matched and solved by RANSAC over the
// correspondences, a few distinct ones, most inliers first.
std::vector<Transform> FeatureGuesses(const ScanPyramid& source_scan,
                                      const ScanPyramid& target_scan, const PreparedPair& prepared,
                                      const BoIcpConfig& config) {
  const int step = std::max(FeatureStep(prepared.search_source.size()),
                            FeatureStep(prepared.search_target.size()));
  const auto source = FeaturesOf(source_scan, prepared.search_source, step, config);
  const auto target = FeaturesOf(target_scan, prepared.search_target.points(), step, config);
  FeatureMatchOptions options;
  options.inlier_distance = 1.5 * source->voxel;
  options.distinct_translation = 3.0 * source->voxel;
  options.seed = config.seed ^ kFeatureSalt;
  options.threads = config.threads;
  std::vector<Transform> guesses;
  for (const FeatureHypothesis& h : FeatureHypotheses(source->points, source->features,
                                                      target->points, target->features, options)) {
    guesses.push_back(h.transform);
  }
  return guesses;
}

// The fitness under which an answer that the target's view refutes
// (kSeenThroughOfNoTrust) says the scans do not overlap (NoOverlapFound).
constexpr double kNoOverlapFitness = 0.1;

// One answer assessed twice: a rival basin that one rung found stays found,
// though a later rung's search may not visit it, so the later assessment
// keeps the smallest margin measured to a rival.
void KeepRivalsFound(const SearchOutcome& earlier, SearchOutcome& later) {
  if (!earlier.features.margin_measured) return;
  if (later.features.margin_measured && later.features.margin <= earlier.features.margin) return;
  later.features.margin = earlier.features.margin;
  later.features.margin_measured = true;
  later.confidence = Confidence(later.features);
}

// Budget::kAuto: the escalation ladder. Each rung runs only while the
// answer kept so far is doubtful, and hands what it learned (its answer, its
// hypotheses) to the next as starts. The rungs share their finest points,
// so the answer kept is the one that fits the most of them (or the latest
// assessment of it); keeping the most confident instead would report the
// luckiest of several estimates.
class Ladder {
 public:
  Ladder(const ScanPyramid& source, const ScanPyramid& target, const BoIcpConfig& config,
         const std::optional<Transform>& prior, const RegistrationCallbacks& callbacks)
      : source_(source),
        target_(target),
        config_(config),
        prior_(prior),
        callbacks_(callbacks),
        prepared_(std::make_shared<const PreparedPair>(PreparePair(source, target, config))),
        frame_(MakeSearchFrame(*prepared_, prior)) {}

  Registered Run(const std::optional<Transform>& guess) {
    const std::optional<Transform> start = prior_ ? prior_ : guess;
    if (start ? PriorRung(*start) : FeatureRung()) return Finish();
    const PairContext pair = MakePairContext(*prepared_, config_);
    StagedSearch search(pair, frame_, config_, callbacks_);
    if (SearchRung(search, /*short_budget=*/true)) return Finish();
    if (!config_.full_search_when_doubtful || NoOverlapFound()) return Finish();
    if (SearchRung(search, /*short_budget=*/false)) return Finish();
    if (config_.retry_when_doubtful) RetryRung();
    return Finish();
  }

 private:
  // The refinement from the prior (or guess), beside the competing basins
  // looked for around it (probes) and anywhere (the feature hypotheses): an
  // ICP from a guess short of the motion can stall in a shallow basin that
  // every probe falls back into, though a better one lies a few voxels on.
  // The feature rung is then not run again.
  bool PriorRung(const Transform& start) {
    const auto started = std::chrono::steady_clock::now();
    std::vector<Transform> starts = {start};
    for (const Transform& probe : ProbesAround(start, frame_.source_centroid, config_))
      starts.push_back(probe);
    learned_ = FeatureGuesses(source_, target_, *prepared_, config_);
    starts.insert(starts.end(), learned_.begin(), learned_.end());
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
    std::vector<Transform> starts = FeatureGuesses(source_, target_, *prepared_, config_);
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

  // Keeps `out` when it fits more of the finest points than the answer kept
  // so far, or ends in its basin: then it is the same answer, assessed again
  // with every rival found so far. True once the kept answer is trusted.
  bool Consider(SearchOutcome&& out, Rung rung, Attempt attempt) {
    const bool same_answer =
        !attempts_.empty() &&
        SameBasin(out.refined.transform, kept_.refined.transform, config_.voxel);
    if (same_answer) KeepRivalsFound(kept_, out);
    if (attempts_.empty() || same_answer ||
        out.refined.score.fitness > kept_.refined.score.fitness) {
      kept_ = std::move(out);
      rung_ = rung;
      kept_index_ = attempts_.size();
    }
    attempts_.push_back(attempt);
    return kept_.confidence >= kTrustedFrom;
  }

  // Every answer so far matched under a tenth of the source and put at least
  // 30 % of it where the target's sensor saw through (a view the check can
  // read): the scans do not overlap, as across a throttled log's gap, and
  // the full search and the retry would find nothing to trust either.
  bool NoOverlapFound() const {
    return std::all_of(attempts_.begin(), attempts_.end(), [](const Attempt& a) {
      return a.fitness < kNoOverlapFitness && a.features.seen_through >= kSeenThroughOfNoTrust;
    });
  }

  Registered Finish() {
    attempts_[kept_index_].kept = true;
    return {std::move(kept_), rung_, std::move(attempts_)};
  }

  const ScanPyramid& source_;
  const ScanPyramid& target_;
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

namespace {

// A registration between the centred clouds: it gets the prior and the
// guess mapped there.
using CentredRegistration = std::function<Registered(const std::optional<Transform>& prior,
                                                     const std::optional<Transform>& guess)>;

// The registration proper, once the settings are final and both scans are
// cropped, centred and downsampled. The engine works between the centred
// clouds; the transforms it takes and gives are mapped at this boundary.

RegistrationResult RegisterScans(const ScanPyramid& source, const ScanPyramid& target,
                                 const BoIcpConfig& config, const std::optional<Transform>& prior,
                                 const std::optional<Transform>& guess,
                                 const CentredRegistration& register_centred,
                                 std::chrono::steady_clock::time_point started) {
  ValidateConfig(config);
  const auto centred = [&](const std::optional<Transform>& T) -> std::optional<Transform> {
    if (!T) return std::nullopt;
    return CentredTransform(source.centre, target.centre, *T);
  };
  const auto uncentred = [&](const Transform& T) {
    return UncentredTransform(source.centre, target.centre, T);
  };
  Registered registered = register_centred(centred(prior), centred(guess));
  SearchOutcome& kept = registered.kept;
  RegistrationResult result;
  result.transform = uncentred(kept.refined.transform);
  result.objective = kept.objective;
  result.fitness = kept.refined.score.fitness;
  result.inlier_rmse = kept.refined.score.inlier_rmse;
  const PyramidLevel& finest = kept.prepared->pyramid.back();
  const InformationMatrix information =
      PlaneInformation(finest.source, finest.target, kept.refined.transform,
                       config.EffectiveInlierDistance(), 3.0 * finest.voxel);
  result.information = MovedInformation(information, target.centre);
  result.unconstrained = UnconstrainedSlides(information, config.EffectiveInlierDistance());
  result.overlap = kept.overlap;
  result.search_reach = SearchReach(kept.box, kept.refined.transform);
  result.probability_better = kept.probability_better;
  result.features = kept.features;
  result.features.constrained_share = ConstrainedShare(information);
  const std::vector<FreeSlide> slides =
      PrincipalSlides(information, config.EffectiveInlierDistance());
  if (!slides.empty())
    result.features.slide_rival = SlideRivalShare(
        RandomSubsample(finest.source, kSlideRivalPoints, config.seed), finest.target,
        kept.refined.transform, slides.front().axis, config.EffectiveInlierDistance());
  result.confidence = std::min(kept.confidence, Confidence(result.features));
  result.doubtful = result.confidence < kTrustedFrom;
  result.gp_mean = kept.gp_mean;
  result.gp_std = kept.gp_std;
  result.answered_by = registered.rung;
  for (const Attempt& attempt : registered.attempts) result.evaluations += attempt.evaluations;
  result.source_points = kept.source_points;
  result.target_points = kept.target_points;
  result.history = std::move(kept.history);
  for (Evaluation& evaluation : result.history) {
    evaluation.initial = uncentred(evaluation.initial);
    evaluation.result = uncentred(evaluation.result);
  }
  result.attempts = std::move(registered.attempts);
  for (Attempt& attempt : result.attempts) attempt.transform = uncentred(attempt.transform);
  result.config = config;
  result.runtime_s = SecondsSince(started);
  return result;
}

// BO-ICP as config.budget says: the ladder or the paper's fixed search.
RegistrationResult RegisterWithBudget(const ScanPyramid& source, const ScanPyramid& target,
                                      const BoIcpConfig& config,
                                      const std::optional<Transform>& prior,
                                      const RegistrationCallbacks& callbacks,
                                      const std::optional<Transform>& guess,
                                      std::chrono::steady_clock::time_point started) {
  return RegisterScans(
      source, target, config, prior, guess,
      [&](const std::optional<Transform>& centred_prior,
          const std::optional<Transform>& centred_guess) {
        return config.budget == Budget::kFixed
                   ? RegisterFixed(source, target, config, centred_prior, callbacks)
                   : Ladder(source, target, config, centred_prior, callbacks).Run(centred_guess);
      },
      started);
}

}  // namespace

RegistrationResult RegisterPair(const Points& source, const Points& target,
                                const BoIcpConfig& requested, const std::optional<Transform>& prior,
                                const RegistrationCallbacks& callbacks,
                                const std::optional<Transform>& guess) {
  const auto started = std::chrono::steady_clock::now();
  BoIcpConfig config = requested;
  std::vector<std::string> auto_fields = ChooseSettingsForPair(source, target, config);
  ValidateConfig(config);
  RegistrationResult result =
      RegisterWithBudget(BuildScanPyramid(source, config), BuildScanPyramid(target, config), config,
                         prior, callbacks, guess, started);
  result.auto_fields = std::move(auto_fields);
  return result;
}

RegistrationResult RegisterPair(const ScanPyramid& source, const ScanPyramid& target,
                                const BoIcpConfig& config, const std::optional<Transform>& prior,
                                const RegistrationCallbacks& callbacks,
                                const std::optional<Transform>& guess) {
  if (!config.automatic.empty()) {
    throw std::invalid_argument("RegisterPair on scan pyramids needs settings chosen beforehand");
  }
  return RegisterWithBudget(source, target, config, prior, callbacks, guess,
                            std::chrono::steady_clock::now());
}

RegistrationResult RefineFromStart(const ScanPyramid& source, const ScanPyramid& target,
                                   const BoIcpConfig& config, const Transform& start,
                                   const RegistrationCallbacks& callbacks) {
  if (!config.automatic.empty()) {
    throw std::invalid_argument("RefineFromStart needs settings chosen beforehand");
  }
  const auto started = std::chrono::steady_clock::now();
  return RegisterScans(
      source, target, config, start, std::nullopt,
      [&](const std::optional<Transform>& centred_start, const std::optional<Transform>&) {
        const auto prepared =
            std::make_shared<const PreparedPair>(PreparePair(source, target, config));
        const SearchFrame frame = MakeSearchFrame(*prepared, *centred_start);
        Registered out;
        out.kept = OutcomeOf(prepared, frame, config);
        RefineAndAssess(out.kept, {frame.anchor}, config, callbacks);
        out.rung = Rung::kPrior;
        out.attempts.push_back(AttemptOf(AttemptKind::kPrior, config, out.kept, 1, 1, started));
        out.attempts.back().kept = true;
        return out;
      },
      started);
}

}  // namespace boicp
