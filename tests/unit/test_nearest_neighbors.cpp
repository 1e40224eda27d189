// The nearest-neighbour index against a brute-force scan, with and without
// the neighbour lists that answer hinted queries without a tree search.

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/icp/preprocess.hpp"
#include "boicp/io/synthetic_scene.hpp"

namespace boicp {
namespace {

struct Answer {
  bool found = false;
  size_t index = 0;
  double squared_distance = 0.0;
};

// The nearest point within the bound by scanning every point, with the
// index's tie rule for a hint: another point replaces it only when strictly
// nearer.
Answer BruteForce(const Points& points, const Point& query, double max_squared,
                  size_t hint = std::numeric_limits<size_t>::max()) {
  Answer best;
  best.squared_distance = max_squared;
  if (hint < points.size()) {
    const double d2 = (points[hint] - query).squaredNorm();
    if (d2 < max_squared) best = {true, hint, d2};
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const double d2 = (points[i] - query).squaredNorm();
    if (d2 < best.squared_distance) best = {true, i, d2};
  }
  return best;
}

Answer WithHint(const NearestNeighborIndex& index, const Point& query, size_t hint,
                double max_squared) {
  Answer a;
  a.found = index.NearestWithHint(query, hint, max_squared, a.index, a.squared_distance);
  return a;
}

// The same point, or a copy of it at the same place (copies tie exactly, and
// which of them a search meets first is its own affair).
void ExpectSame(const Points& points, const Answer& expected, const Answer& actual,
                const std::string& what) {
  ASSERT_EQ(expected.found, actual.found) << what;
  if (!expected.found) return;
  EXPECT_EQ(points[expected.index], points[actual.index])
      << what << ": expected point " << expected.index << ", got " << actual.index;
  EXPECT_EQ(expected.squared_distance, actual.squared_distance) << what;  // bit for bit
}

// Hinted queries as ICP makes them: a target point moved off the surface by
// up to `spread`, hinted with a target point near it, gated at `gate`.
void CheckHintedQueries(const Points& target, double spread, double gate, uint64_t seed) {
  const NearestNeighborIndex plain(target);
  const NearestNeighborIndex listed(target, /*neighbour_lists=*/true);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, target.size() - 1);
  std::uniform_real_distribution<double> offset(-spread, spread);
  const double max_squared = gate * gate;
  for (int q = 0; q < 3000; ++q) {
    const size_t near = pick(rng);
    const Point query = target[near] + Point(offset(rng), offset(rng), offset(rng));
    // The hint is the point the query was made from, or a random one.
    const size_t hint = q % 4 == 0 ? pick(rng) : near;
    const Answer expected = BruteForce(target, query, max_squared, hint);
    const std::string what = "query " + std::to_string(q) + ", hint " + std::to_string(hint);
    ExpectSame(target, expected, WithHint(plain, query, hint, max_squared), what + " (tree)");
    ExpectSame(target, expected, WithHint(listed, query, hint, max_squared), what + " (lists)");
  }
}

TEST(NearestNeighbors, HintedQueriesMatchABruteForceScanWithAndWithoutNeighbourLists) {
  const Points street = VoxelDownsample(MakeSyntheticStreet(3, 20.0), 0.3);
  ASSERT_GT(street.size(), 1000u);
  CheckHintedQueries(street, 0.2, 0.9, 1);  // near the surface, within a step of ICP
  CheckHintedQueries(street, 1.0, 0.9, 2);  // far off it, many beyond the gate
}

TEST(NearestNeighbors, NeighbourListsHandleCloudsSmallerThanAListAndRepeatedPoints) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (size_t n : {size_t{1}, size_t{2}, NearestNeighborIndex::kNeighbourListSize,
                   NearestNeighborIndex::kNeighbourListSize + 1,
                   NearestNeighborIndex::kNeighbourListSize + 2}) {
    Points cloud;
    for (size_t i = 0; i < n; ++i) cloud.emplace_back(coordinate(rng), coordinate(rng), 0.0);
    CheckHintedQueries(cloud, 0.5, 10.0, n);
  }
  // More copies of one point than a list holds, beside a few others.
  Points repeated(NearestNeighborIndex::kNeighbourListSize + 5, Point(0.5, 0.5, 0.5));
  for (int i = 0; i < 20; ++i) repeated.emplace_back(coordinate(rng), coordinate(rng), 0.2);
  CheckHintedQueries(repeated, 0.3, 2.0, 99);
}

TEST(NearestNeighbors, UnhintedQueriesMatchABruteForceScan) {
  const Points street = VoxelDownsample(MakeSyntheticStreet(3, 20.0), 0.3);
  const NearestNeighborIndex index(street, /*neighbour_lists=*/true);
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<size_t> pick(0, street.size() - 1);
  std::uniform_real_distribution<double> offset(-1.0, 1.0);
  for (int q = 0; q < 2000; ++q) {
    const Point query = street[pick(rng)] + Point(offset(rng), offset(rng), offset(rng));
    Answer actual;
    actual.found = index.Nearest(query, 0.81, actual.index, actual.squared_distance);
    ExpectSame(street, BruteForce(street, query, 0.81), actual, "query " + std::to_string(q));
  }
}

// Leaf size trades build time against search time only: the k nearest
// points and their distances are the brute force's, for any leaf size.
TEST(NearestNeighbors, EveryLeafSizeGivesTheBruteForceKNearest) {
  const Points street = VoxelDownsample(MakeSyntheticStreet(3, 20.0), 0.3);
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<size_t> pick(0, street.size() - 1);
  std::uniform_real_distribution<double> offset(-1.0, 1.0);
  Points queries;
  for (int q = 0; q < 500; ++q) {
    queries.push_back(street[pick(rng)] + Point(offset(rng), offset(rng), offset(rng)));
  }
  for (size_t leaf : {size_t{1}, NearestNeighborIndex::kDefaultLeafSize,
                      NearestNeighborIndex::kFewQueriesLeafSize, street.size() + 1}) {
    const NearestNeighborIndex index(street, /*neighbour_lists=*/false, leaf);
    std::vector<size_t> indices;
    std::vector<double> squared;
    for (const Point& query : queries) {
      index.KNearest(query, 3, std::numeric_limits<double>::infinity(), indices, squared);
      std::vector<double> expected;
      for (const Point& p : street) expected.push_back((p - query).squaredNorm());
      std::sort(expected.begin(), expected.end());
      ASSERT_EQ(indices.size(), 3u) << "leaf " << leaf;
      for (size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(squared[k], expected[k]) << "leaf " << leaf << ", neighbour " << k;
        EXPECT_EQ((street[indices[k]] - query).squaredNorm(), squared[k]) << "leaf " << leaf;
      }
    }
  }
}

}  // namespace
}  // namespace boicp
