#include "boicp/registration/feature_hypotheses.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "boicp/util/parallel_for.hpp"

namespace boicp {
namespace {

// Below this many mutual matches the scene is too poor in distinctive points
// for mutual filtering to leave RANSAC anything; one-way matches do.
constexpr size_t kFewestMutualMatches = 30;

// Source descriptors are compared with all target ones this many at a time:
// one block's products (about 3 MB for 6000 targets) stay in cache, and the
// fixed size keeps every sum, so every nearest neighbour, independent of the
// thread count.
constexpr Eigen::Index kMatchBlock = 128;

// The draws are split into this many chunks, each with its own generator, so
// the draws and their merge order do not depend on the thread count.
constexpr int kRansacChunks = 16;

using DescriptorMatrix = Eigen::Matrix<float, 33, Eigen::Dynamic>;

// The descriptors that say something (not all zero) and their point indices.
struct DescriptorSet {
  DescriptorMatrix descriptors;
  std::vector<size_t> points;
};

struct Correspondence {
  size_t source = 0;
  size_t target = 0;
};

// Column k of each is the k-th correspondence's point, so that scoring a
// hypothesis streams through memory.
struct MatchedPoints {
  Eigen::Matrix3Xd source;
  Eigen::Matrix3Xd target;
};

struct RansacCandidate {
  Transform transform = Transform::Identity();
  int inliers = 0;
  int64_t draw = 0;  // global draw index: the deterministic tie-break
};

void CheckMatchOptions(const FeatureMatchOptions& o) {
  const auto fail = [](const std::string& what) {
    throw InputError("feature hypotheses: " + what);
  };
  if (!(o.inlier_distance > 0.0) || !std::isfinite(o.inlier_distance)) {
    fail("inlier_distance must be a positive number of metres");
  }
  if (o.iterations < 1) fail("iterations must be at least 1");
  if (!(o.edge_ratio > 0.0 && o.edge_ratio <= 1.0)) fail("edge_ratio must be in (0, 1]");
  if (o.max_hypotheses < 1) fail("max_hypotheses must be at least 1");
  if (!(o.distinct_translation > 0.0) || !std::isfinite(o.distinct_translation)) {
    fail("distinct_translation must be a positive number of metres");
  }
  if (!(o.distinct_rotation >= 0.0) || !std::isfinite(o.distinct_rotation)) {
    fail("distinct_rotation must be a non-negative number of radians");
  }
  if (o.threads < 1) fail("threads must be at least 1");
}

void CheckFeatureCount(const Points& points, const FpfhFeatures& features, const char* cloud) {
  if (static_cast<size_t>(features.cols()) != points.size()) {
    throw InputError(std::string("feature hypotheses: ") + std::to_string(features.cols()) + " " +
                     cloud + " features for " + std::to_string(points.size()) + " points");
  }
}

// An all-zero descriptor belongs to a point without neighbours: every such
// point would match every other, so they are left out.
DescriptorSet InformativeDescriptors(const FpfhFeatures& features) {
  DescriptorSet set;
  for (Eigen::Index i = 0; i < features.cols(); ++i) {
    if (!features.col(i).isZero()) set.points.push_back(static_cast<size_t>(i));
  }
  set.descriptors.resize(33, static_cast<Eigen::Index>(set.points.size()));
  for (size_t k = 0; k < set.points.size(); ++k) {
    set.descriptors.col(static_cast<Eigen::Index>(k)) =
        features.col(static_cast<Eigen::Index>(set.points[k]));
  }
  return set;
}

// Each descriptor's nearest one in the other set, both ways, with the lowest
// index winning a tie.
struct NearestDescriptors {
  std::vector<size_t> source_to_target;
  std::vector<size_t> target_to_source;
};

// The nearest source to each target among the sources seen so far.
struct NearestSources {
  explicit NearestSources(Eigen::Index targets = 0)
      : distance(static_cast<size_t>(targets), std::numeric_limits<float>::infinity()),
        source(static_cast<size_t>(targets), 0) {}

  // Keeps the lower source index on a tie, so that merging the partial
  // results of disjoint sources gives the same answer in any order.
  void Merge(const NearestSources& other) {
    for (size_t t = 0; t < distance.size(); ++t) {
      if (other.distance[t] < distance[t] ||
          (other.distance[t] == distance[t] && other.source[t] < source[t])) {
        distance[t] = other.distance[t];
        source[t] = other.source[t];
      }
    }
  }

  std::vector<float> distance;
  std::vector<size_t> source;
};

// Compares sources [first, first + count) with every target through the
// squared distances |s|^2 + |t|^2 - 2 s.t, all from one matrix product: a
// kd-tree prunes badly in 33 dimensions (nanoflann's exact search took twice
// as long on 6000 descriptors a side), and one matrix answers both directions.
// Writes the sources' nearest targets to `source_to_target` and offers the
// sources to `nearest_sources`, in ascending order so that ties keep the
// lowest index.
void CompareBlock(const DescriptorMatrix& source, Eigen::Index first, Eigen::Index count,
                  const Eigen::Matrix<float, Eigen::Dynamic, 33>& target_rows,
                  const Eigen::VectorXf& target_norms, Eigen::MatrixXf& products,
                  std::vector<size_t>& source_to_target, NearestSources& nearest_sources) {
  const Eigen::Index targets = target_rows.rows();
  products.leftCols(count).noalias() = target_rows * source.middleCols(first, count);
  float* best_distance = nearest_sources.distance.data();
  size_t* best_source = nearest_sources.source.data();
  for (Eigen::Index q = 0; q < count; ++q) {
    const auto s = static_cast<size_t>(first + q);
    const float source_norm = source.col(first + q).squaredNorm();
    const float* product = products.col(q).data();
    float best = std::numeric_limits<float>::infinity();
    Eigen::Index best_target = 0;
    for (Eigen::Index r = 0; r < targets; ++r) {
      const float distance = (source_norm + target_norms[r]) - 2.0F * product[r];
      if (distance < best) {
        best = distance;
        best_target = r;
      }
      if (distance < best_distance[r]) {
        best_distance[r] = distance;
        best_source[r] = s;
      }
    }
    source_to_target[s] = static_cast<size_t>(best_target);
  }
}

// Brute force in blocks of kMatchBlock sources; each thread's range keeps
// its own nearest sources, merged afterwards. Time grows with the product of
// the two sizes, which the search voxel keeps to thousands of points a side.
NearestDescriptors FindNearestDescriptors(const DescriptorMatrix& source,
                                          const DescriptorMatrix& target, int threads) {
  const Eigen::Matrix<float, Eigen::Dynamic, 33> target_rows = target.transpose();
  const Eigen::VectorXf target_norms = target.colwise().squaredNorm().transpose();
  const Eigen::Index sources = source.cols();
  const auto blocks = static_cast<size_t>((sources + kMatchBlock - 1) / kMatchBlock);
  NearestDescriptors nearest;
  nearest.source_to_target.resize(static_cast<size_t>(sources));
  // Slot `begin` holds the result of the range starting at block `begin`.
  std::vector<NearestSources> per_range(blocks);
  ParallelForRanges(blocks, threads, [&](size_t begin, size_t end) {
    Eigen::MatrixXf products(target.cols(), kMatchBlock);
    NearestSources range_nearest(target.cols());
    for (size_t b = begin; b < end; ++b) {
      const Eigen::Index first = static_cast<Eigen::Index>(b) * kMatchBlock;
      CompareBlock(source, first, std::min(kMatchBlock, sources - first), target_rows, target_norms,
                   products, nearest.source_to_target, range_nearest);
    }
    per_range[begin] = std::move(range_nearest);
  });
  NearestSources merged(target.cols());
  for (const NearestSources& range_nearest : per_range) {
    if (!range_nearest.distance.empty()) merged.Merge(range_nearest);
  }
  nearest.target_to_source = std::move(merged.source);
  return nearest;
}

// Mutual nearest neighbours in descriptor space, in source order; the
// source->target nearest neighbours when too few are mutual.
std::vector<Correspondence> MatchDescriptors(const DescriptorSet& source,
                                             const DescriptorSet& target, int threads) {
  const NearestDescriptors nearest =
      FindNearestDescriptors(source.descriptors, target.descriptors, threads);
  const std::vector<size_t>& forward = nearest.source_to_target;
  const std::vector<size_t>& backward = nearest.target_to_source;
  std::vector<Correspondence> mutual;
  std::vector<Correspondence> one_way;
  for (size_t s = 0; s < forward.size(); ++s) {
    const Correspondence c{source.points[s], target.points[forward[s]]};
    one_way.push_back(c);
    if (backward[forward[s]] == s) mutual.push_back(c);
  }
  return mutual.size() >= kFewestMutualMatches ? mutual : one_way;
}

MatchedPoints GatherMatchedPoints(const Points& source, const Points& target,
                                  const std::vector<Correspondence>& matches) {
  MatchedPoints matched;
  matched.source.resize(3, static_cast<Eigen::Index>(matches.size()));
  matched.target.resize(3, static_cast<Eigen::Index>(matches.size()));
  for (size_t k = 0; k < matches.size(); ++k) {
    matched.source.col(static_cast<Eigen::Index>(k)) = source[matches[k].source];
    matched.target.col(static_cast<Eigen::Index>(k)) = target[matches[k].target];
  }
  return matched;
}

// SplitMix64's finaliser: spreads (seed, chunk) over the generator's seed space.
uint64_t SplitMixSeed(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

uint64_t ChunkSeed(uint64_t seed, int chunk) {
  return SplitMixSeed(seed ^ SplitMixSeed(static_cast<uint64_t>(chunk) + 1));
}

// Unbiased integer in [0, bound) by rejection, written out because
// std::uniform_int_distribution's sequence is library-specific.
size_t DrawIndex(size_t bound, std::mt19937_64& rng) {
  const uint64_t threshold = (0 - static_cast<uint64_t>(bound)) % bound;
  for (;;) {
    const uint64_t r = rng();
    if (r >= threshold) return static_cast<size_t>(r % bound);
  }
}

// Three distinct correspondence indices. Precondition: count >= 3.
std::array<Eigen::Index, 3> DrawTriple(size_t count, std::mt19937_64& rng) {
  const size_t a = DrawIndex(count, rng);
  size_t b = DrawIndex(count, rng);
  while (b == a) b = DrawIndex(count, rng);
  size_t c = DrawIndex(count, rng);
  while (c == a || c == b) c = DrawIndex(count, rng);
  return {static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b), static_cast<Eigen::Index>(c)};
}

// A rigid motion preserves lengths, so a triple whose source and target
// edges differ by more than the ratio holds a wrong match: rejecting it here
// costs nine subtractions instead of a fit and a scoring pass.
bool EdgesAgree(const Eigen::Matrix3d& source, const Eigen::Matrix3d& target, double ratio) {
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3;
    const double in_source = (source.col(a) - source.col(b)).norm();
    const double in_target = (target.col(a) - target.col(b)).norm();
    if (in_source < ratio * in_target || in_target < ratio * in_source) return false;
  }
  return true;
}

// True when every height of the triangle is at least `min_height`: the
// rotation fitted to a thinner one swings with noise of that size.
bool WideTriangle(const Eigen::Matrix3d& corners, double min_height) {
  const Point ab = corners.col(1) - corners.col(0);
  const Point ac = corners.col(2) - corners.col(0);
  const Point bc = corners.col(2) - corners.col(1);
  const double longest = std::max({ab.norm(), ac.norm(), bc.norm()});
  const double twice_area = ab.cross(ac).norm();
  return twice_area >= min_height * longest && longest > 0.0;
}

int CountInliers(const Transform& T, const MatchedPoints& matched, double squared_gate) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  int inliers = 0;
  for (Eigen::Index k = 0; k < matched.source.cols(); ++k) {
    const Eigen::Vector3d r = R * matched.source.col(k) + t - matched.target.col(k);
    inliers += r.squaredNorm() < squared_gate ? 1 : 0;
  }
  return inliers;
}

bool SamePose(const Transform& a, const Transform& b, const FeatureMatchOptions& options) {
  const double translation = (a.topRightCorner<3, 1>() - b.topRightCorner<3, 1>()).norm();
  if (!(translation < options.distinct_translation)) return false;
  const Eigen::Matrix3d relative = a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>();
  const double cos_angle = std::clamp((relative.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(cos_angle) < options.distinct_rotation;
}

// The strict order of the result: more inliers first, then the earlier draw.
bool RanksBefore(const RansacCandidate& a, const RansacCandidate& b) {
  if (a.inliers != b.inliers) return a.inliers > b.inliers;
  return a.draw < b.draw;
}

// Keeps the best `capacity` candidates of a chunk, one per pose: a candidate
// at a kept one's pose replaces it only when it ranks before it.
void KeepCandidate(const RansacCandidate& candidate, size_t capacity,
                   const FeatureMatchOptions& options, std::vector<RansacCandidate>& kept) {
  if (kept.size() == capacity && !RanksBefore(candidate, kept.back())) return;
  for (RansacCandidate& existing : kept) {
    if (SamePose(existing.transform, candidate.transform, options)) {
      if (RanksBefore(candidate, existing)) existing = candidate;
      std::sort(kept.begin(), kept.end(), RanksBefore);
      return;
    }
  }
  if (kept.size() == capacity) kept.pop_back();
  kept.insert(std::upper_bound(kept.begin(), kept.end(), candidate, RanksBefore), candidate);
}

// Draws [begin, end) of the RANSAC, with the chunk's own generator.
std::vector<RansacCandidate> RansacChunk(const MatchedPoints& matched, int64_t begin, int64_t end,
                                         uint64_t seed, size_t capacity,
                                         const FeatureMatchOptions& options) {
  std::mt19937_64 rng(seed);
  const auto count = static_cast<size_t>(matched.source.cols());
  const double squared_gate = options.inlier_distance * options.inlier_distance;
  std::vector<RansacCandidate> kept;
  for (int64_t draw = begin; draw < end; ++draw) {
    const std::array<Eigen::Index, 3> triple = DrawTriple(count, rng);
    Eigen::Matrix3d source_corners;
    Eigen::Matrix3d target_corners;
    for (int c = 0; c < 3; ++c) {
      source_corners.col(c) = matched.source.col(triple[static_cast<size_t>(c)]);
      target_corners.col(c) = matched.target.col(triple[static_cast<size_t>(c)]);
    }
    if (!EdgesAgree(source_corners, target_corners, options.edge_ratio)) continue;
    if (!WideTriangle(source_corners, options.inlier_distance)) continue;
    RansacCandidate candidate;
    candidate.transform = Eigen::umeyama(source_corners, target_corners, false);
    candidate.inliers = CountInliers(candidate.transform, matched, squared_gate);
    candidate.draw = draw;
    if (candidate.inliers >= 3) KeepCandidate(candidate, capacity, options, kept);
  }
  return kept;
}

// The draws of every chunk (run in parallel), merged in rank order.
std::vector<RansacCandidate> RansacCandidates(const MatchedPoints& matched, size_t capacity,
                                              const FeatureMatchOptions& options) {
  std::vector<std::vector<RansacCandidate>> chunks(kRansacChunks);
  ParallelFor(kRansacChunks, options.threads, [&](size_t chunk) {
    const int64_t iterations = options.iterations;
    const auto c = static_cast<int64_t>(chunk);
    chunks[chunk] =
        RansacChunk(matched, iterations * c / kRansacChunks, iterations * (c + 1) / kRansacChunks,
                    ChunkSeed(options.seed, static_cast<int>(chunk)), capacity, options);
  });
  std::vector<RansacCandidate> merged;
  for (const std::vector<RansacCandidate>& chunk : chunks) {
    merged.insert(merged.end(), chunk.begin(), chunk.end());
  }
  std::sort(merged.begin(), merged.end(), RanksBefore);
  return merged;
}

// The least-squares fit to the candidate's inliers, kept when it has at least
// as many: three points fix a pose only to their noise, its inliers better.
RansacCandidate Reestimate(const RansacCandidate& candidate, const MatchedPoints& matched,
                           double squared_gate) {
  std::vector<Eigen::Index> inliers;
  const Eigen::Matrix3d R = candidate.transform.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = candidate.transform.topRightCorner<3, 1>();
  for (Eigen::Index k = 0; k < matched.source.cols(); ++k) {
    const Eigen::Vector3d r = R * matched.source.col(k) + t - matched.target.col(k);
    if (r.squaredNorm() < squared_gate) inliers.push_back(k);
  }
  if (inliers.size() < 3) return candidate;
  Eigen::Matrix3Xd source(3, static_cast<Eigen::Index>(inliers.size()));
  Eigen::Matrix3Xd target(3, static_cast<Eigen::Index>(inliers.size()));
  for (size_t k = 0; k < inliers.size(); ++k) {
    source.col(static_cast<Eigen::Index>(k)) = matched.source.col(inliers[k]);
    target.col(static_cast<Eigen::Index>(k)) = matched.target.col(inliers[k]);
  }
  RansacCandidate refit = candidate;
  refit.transform = Eigen::umeyama(source, target, false);
  refit.inliers = CountInliers(refit.transform, matched, squared_gate);
  return refit.inliers >= candidate.inliers ? refit : candidate;
}

// The first `limit` candidates of a ranked list that are distinct from every
// earlier pick.
std::vector<RansacCandidate> FirstDistinct(const std::vector<RansacCandidate>& ranked, size_t limit,
                                           const FeatureMatchOptions& options) {
  std::vector<RansacCandidate> picked;
  for (const RansacCandidate& candidate : ranked) {
    if (picked.size() == limit) break;
    const bool seen = std::any_of(picked.begin(), picked.end(), [&](const RansacCandidate& p) {
      return SamePose(p.transform, candidate.transform, options);
    });
    if (!seen) picked.push_back(candidate);
  }
  return picked;
}

}  // namespace

std::vector<FeatureHypothesis> FeatureHypotheses(const Points& source,
                                                 const FpfhFeatures& source_features,
                                                 const Points& target,
                                                 const FpfhFeatures& target_features,
                                                 const FeatureMatchOptions& options) {
  CheckMatchOptions(options);
  CheckFeatureCount(source, source_features, "source");
  CheckFeatureCount(target, target_features, "target");
  const DescriptorSet source_set = InformativeDescriptors(source_features);
  const DescriptorSet target_set = InformativeDescriptors(target_features);
  if (source_set.points.size() < 3 || target_set.points.size() < 3) return {};
  const MatchedPoints matched = GatherMatchedPoints(
      source, target, MatchDescriptors(source_set, target_set, options.threads));
  if (matched.source.cols() < 3) return {};

  const auto wanted = static_cast<size_t>(options.max_hypotheses);
  // Room for the runners-up that re-estimation may promote past the leaders.
  const size_t pool = 2 * wanted + 4;
  const std::vector<RansacCandidate> drawn = RansacCandidates(matched, pool, options);
  std::vector<RansacCandidate> refined = FirstDistinct(drawn, pool, options);
  const double squared_gate = options.inlier_distance * options.inlier_distance;
  for (RansacCandidate& candidate : refined)
    candidate = Reestimate(candidate, matched, squared_gate);
  std::sort(refined.begin(), refined.end(), RanksBefore);

  std::vector<FeatureHypothesis> hypotheses;
  for (const RansacCandidate& candidate : FirstDistinct(refined, wanted, options)) {
    hypotheses.push_back({candidate.transform, candidate.inliers});
  }
  return hypotheses;
}

}  // namespace boicp
