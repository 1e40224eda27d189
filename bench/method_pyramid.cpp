// pyramid: the paper's brute-force baseline. Nested like BO-ICP: a rotation
// grid, then a translation grid with the best rotation fixed. Each stage
// scores a 12^d grid over the search box by a radius-based nearest-neighbour
// fit, keeps the 10 best cells and refines each three times with a 6^d grid
// around it, every level a third of the previous spacing. ICP then runs from
// the 10 best translation candidates and the best result is refined like
// every other method's.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "boicp/icp/alignment_score.hpp"
#include "boicp/icp/preprocess.hpp"
#include "boicp/registration/refinement.hpp"
#include "boicp/registration/search_space.hpp"
#include "boicp/util/parallel_for.hpp"
#include "methods.hpp"

namespace boicp::bench {
namespace {

struct PyramidBudget {
  int initial_per_axis = 12;
  int refine_per_axis = 6;
  int keep = 10;
  int levels = 3;
  size_t score_points = 1000;  // source points each grid score uses (seeded subsample)
};

PyramidBudget BudgetFor(bool quick) {
  PyramidBudget budget;
  if (quick) {
    budget.initial_per_axis = 8;
    budget.refine_per_axis = 4;
    budget.keep = 5;
    budget.score_points = 300;
  }
  return budget;
}

struct Candidate {
  Eigen::VectorXd u;  // in the unit box of the stage's SearchSpace
  double fit = 0.0;   // fraction of score points with a target neighbour within the radius
};

// Scores many unit-box points in parallel; each score is a serial count, so
// the result does not depend on the thread count.
class GridScorer {
 public:
  GridScorer(const Points& points, const NearestNeighborIndex& target, double radius, int threads)
      : points_(points), target_(target), radius_sq_(radius * radius), threads_(threads) {}

  void Score(const SearchSpace& space, std::vector<Candidate>& candidates) {
    const size_t n = candidates.size();
    ParallelFor(n, threads_, [&](size_t k) {
      const Transform T = space.ToTransform(candidates[k].u);
      const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
      const Eigen::Vector3d t = T.topRightCorner<3, 1>();
      size_t inliers = 0, index = 0;
      double sq_distance = 0.0;
      for (const Point& p : points_) {
        inliers += target_.Nearest(R * p + t, radius_sq_, index, sq_distance) ? 1 : 0;
      }
      candidates[k].fit = static_cast<double>(inliers) / static_cast<double>(points_.size());
    });
    evaluations_ += static_cast<int>(n);
  }
  int evaluations() const { return evaluations_; }

 private:
  const Points& points_;
  const NearestNeighborIndex& target_;
  double radius_sq_;
  int threads_;
  int evaluations_ = 0;
};

// per_axis points per dimension at offsets (2 (i + 0.5) / per_axis - 1) * half_width
// around centre; periodic coordinates wrap, the others are clamped into [0, 1].
std::vector<Candidate> Grid(const Eigen::VectorXd& centre, double half_width, int per_axis,
                            const std::vector<bool>& periodic) {
  const int d = static_cast<int>(centre.size());
  size_t count = 1;
  for (int k = 0; k < d; ++k) count *= static_cast<size_t>(per_axis);
  std::vector<Candidate> grid(count);
  for (size_t flat = 0; flat < count; ++flat) {
    Eigen::VectorXd u = centre;
    size_t rest = flat;
    for (int k = 0; k < d; ++k) {
      const auto i = static_cast<double>(rest % static_cast<size_t>(per_axis));
      rest /= static_cast<size_t>(per_axis);
      u[k] += (2.0 * (i + 0.5) / per_axis - 1.0) * half_width;
      u[k] = periodic[k] ? u[k] - std::floor(u[k]) : std::clamp(u[k], 0.0, 1.0);
    }
    grid[flat].u = u;
  }
  return grid;
}

// Best first; ties keep grid order so the result is reproducible.
void SortByFit(std::vector<Candidate>& candidates) {
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.fit > b.fit; });
}

std::vector<Candidate> PyramidStage(const SearchSpace& space, GridScorer& scorer,
                                    const PyramidBudget& budget) {
  const KernelInputs inputs = space.Inputs();  // an Euler-angle box
  std::vector<bool> periodic;
  for (int k = 0; k < inputs.dimension(); ++k) {
    periodic.push_back(inputs[k] == InputKind::kPeriodic);
  }
  const Eigen::VectorXd middle = Eigen::VectorXd::Constant(space.dimension(), 0.5);
  std::vector<Candidate> coarse = Grid(middle, 0.5, budget.initial_per_axis, periodic);
  scorer.Score(space, coarse);
  SortByFit(coarse);
  coarse.resize(std::min<size_t>(coarse.size(), static_cast<size_t>(budget.keep)));

  std::vector<Candidate> refined;
  for (const Candidate& seed : coarse) {
    Candidate best = seed;
    double half_width = 1.0 / budget.initial_per_axis;  // one coarse cell either side
    for (int level = 0; level < budget.levels && space.dimension() > 0; ++level) {
      std::vector<Candidate> local = Grid(best.u, half_width, budget.refine_per_axis, periodic);
      scorer.Score(space, local);
      SortByFit(local);
      if (local.front().fit > best.fit) best = local.front();
      half_width /= 3.0;
    }
    refined.push_back(best);
  }
  SortByFit(refined);
  return refined;
}

}  // namespace

RegistrationResult RunPyramid(const Points& source, const Points& target, const BoIcpConfig& config,
                              bool quick) {
  const PyramidBudget budget = BudgetFor(quick);
  const PreparedPair pair = PreparePair(source, target, config);
  const Points score_points = RandomSubsample(pair.search_source, budget.score_points, config.seed);
  const double gate = config.EffectiveMaxCorrespondence();
  GridScorer scorer(score_points, pair.search_target, gate, config.threads);

  // The same box as BO-ICP: centroids on top of each other, rotations about them.
  Transform anchor = Transform::Identity();
  anchor.topRightCorner<3, 1>() =
      Centroid(pair.search_target.points()) - Centroid(pair.search_source);
  const Point pivot = Centroid(pair.search_source) + anchor.topRightCorner<3, 1>();

  const SearchSpace rotation_space =
      MakeSearchSpace(anchor, pivot, config.rotation_bounds, Eigen::Vector3d::Zero());
  const std::vector<Candidate> rotations = PyramidStage(rotation_space, scorer, budget);
  const SearchSpace translation_space =
      MakeSearchSpace(rotation_space.ToTransform(rotations.front().u), pivot,
                      Eigen::Vector3d::Zero(), config.translation_bounds);
  const std::vector<Candidate> translations = PyramidStage(translation_space, scorer, budget);

  Transform best = Transform::Identity();
  double best_objective = std::numeric_limits<double>::infinity();
  for (const Candidate& candidate : translations) {
    const Transform T =
        AlignPointToPoint(pair.search_source, pair.search_target,
                          translation_space.ToTransform(candidate.u), SearchIcpOptions(config))
            .transform;
    const double objective =
        ScoreAlignment(pair.search_source, pair.search_target, T, gate, config.threads)
            .truncated_mean;
    if (objective < best_objective) {
      best_objective = objective;
      best = T;
    }
  }

  RegistrationResult output;
  output.transform = UncentredTransform(pair.source_centre, pair.target_centre,
                                        RefineCoarseToFine({best}, pair, config).transform);
  output.evaluations = scorer.evaluations() + static_cast<int>(translations.size());
  output.source_points = pair.search_source.size();
  output.target_points = pair.search_target.size();
  output.config = config;
  return output;
}

}  // namespace boicp::bench
