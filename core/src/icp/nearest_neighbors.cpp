#include "boicp/icp/nearest_neighbors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <nanoflann.hpp>

namespace boicp {
namespace {

// nanoflann's dataset adaptor over our point vector.
struct PointsAdaptor {
  Points points;
  size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return points[i][static_cast<int>(dim)]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox&) const {
    return false;
  }
};

// Keeps the single closest point but starts with a finite radius, so subtrees
// farther than the correspondence gate are never visited.
class BoundedNearestResult {
 public:
  explicit BoundedNearestResult(double max_squared_distance) : worst_(max_squared_distance) {}
  // Starts from a known candidate: only strictly closer points replace it.
  BoundedNearestResult(double squared_distance, size_t index)
      : worst_(squared_distance), index_(index), found_(true) {}
  bool addPoint(double squared_distance, size_t index) {
    if (squared_distance < worst_) {
      worst_ = squared_distance;
      index_ = index;
      found_ = true;
    }
    return true;
  }
  double worstDist() const { return worst_; }
  bool full() const { return found_; }
  size_t index() const { return index_; }

 private:
  double worst_;
  size_t index_ = 0;
  bool found_ = false;
};

// nanoflann's L2 metric, term for term, so that a distance computed here is
// bit for bit the one a tree search computes for the same point.
double SquaredDistance(const Point& query, const Point& point) {
  double result = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double diff = query[axis] - point[axis];
    result += diff * diff;
  }
  return result;
}

// A search concludes from a neighbour list only with this relative room to
// spare, so rounding cannot make it miss a closer point.
constexpr double kListProofMargin = 1e-9;

using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>,
                                        PointsAdaptor, 3, size_t>;

}  // namespace

struct NearestNeighborIndex::Tree {
  Tree(Points pts, size_t leaf_size)
      : adaptor{std::move(pts)},
        kdtree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(leaf_size)) {}
  PointsAdaptor adaptor;
  KdTree kdtree;
  // Point i's nearest other points are neighbours[i * kNeighbourListSize ...]
  // (padded with i itself when the cloud is smaller), and no point outside
  // that list is nearer to point i than reach[i] metres (+infinity when the
  // list holds every other point). Empty without neighbour lists.
  std::vector<uint32_t> neighbours;
  std::vector<double> reach;

  void BuildNeighbourLists() {
    constexpr size_t k = kNeighbourListSize;
    const Points& points = adaptor.points;
    neighbours.assign(points.size() * k, 0);
    reach.assign(points.size(), std::numeric_limits<double>::infinity());
    std::array<size_t, k + 1> found_index;
    std::array<double, k + 1> found_squared;
    for (size_t i = 0; i < points.size(); ++i) {
      const size_t found =
          kdtree.knnSearch(points[i].data(), k + 1, found_index.data(), found_squared.data());
      uint32_t* list = &neighbours[i * k];
      size_t kept = 0;
      for (size_t r = 0; r < found && kept < k; ++r) {
        if (found_index[r] == i) continue;
        list[kept++] = static_cast<uint32_t>(found_index[r]);
        // Every point the search did not return is at least this far away.
        if (found == k + 1) reach[i] = std::sqrt(found_squared[r]);
      }
      for (; kept < k; ++kept) list[kept] = static_cast<uint32_t>(i);
    }
  }
};

NearestNeighborIndex::NearestNeighborIndex(Points points, bool neighbour_lists, size_t leaf_size)
    : tree_(std::make_unique<Tree>(std::move(points), std::max<size_t>(leaf_size, 1))) {
  if (tree_->adaptor.points.empty())
    throw InputError("nearest-neighbour index: empty target cloud");
  // The lists hold 32-bit indices: a larger cloud is searched in the tree alone.
  if (neighbour_lists && tree_->adaptor.points.size() < std::numeric_limits<uint32_t>::max()) {
    tree_->BuildNeighbourLists();
  }
}

NearestNeighborIndex::~NearestNeighborIndex() = default;
NearestNeighborIndex::NearestNeighborIndex(NearestNeighborIndex&&) noexcept = default;
NearestNeighborIndex& NearestNeighborIndex::operator=(NearestNeighborIndex&&) noexcept = default;

bool NearestNeighborIndex::Nearest(const Point& query, double max_squared_distance, size_t& index,
                                   double& squared_distance) const {
  BoundedNearestResult result(max_squared_distance);
  tree_->kdtree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  if (!result.full()) return false;
  index = result.index();
  squared_distance = result.worstDist();
  return true;
}

bool NearestNeighborIndex::NearestWithHint(const Point& query, size_t hint,
                                           double max_squared_distance, size_t& index,
                                           double& squared_distance) const {
  const double hint_squared = SquaredDistance(query, tree_->adaptor.points[hint]);
  if (!(hint_squared < max_squared_distance)) {
    return Nearest(query, max_squared_distance, index, squared_distance);
  }
  if (!tree_->reach.empty()) {
    // Every point outside the hint's list is at least reach away from the
    // hint, so at least reach - |query - hint| from the query: when the best
    // of the hint and its list is nearer than that, it is the answer.
    double best = hint_squared;
    size_t best_index = hint;
    const uint32_t* list = &tree_->neighbours[hint * kNeighbourListSize];
    for (size_t r = 0; r < kNeighbourListSize; ++r) {
      const double d2 = SquaredDistance(query, tree_->adaptor.points[list[r]]);
      if (d2 < best) {
        best = d2;
        best_index = list[r];
      }
    }
    const double others_beyond =
        (tree_->reach[hint] - std::sqrt(hint_squared)) * (1.0 - kListProofMargin);
    if (others_beyond > 0.0 && best < others_beyond * others_beyond) {
      index = best_index;
      squared_distance = best;
      return true;
    }
  }
  BoundedNearestResult result(hint_squared, hint);
  tree_->kdtree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  index = result.index();
  squared_distance = result.worstDist();
  return true;
}

void NearestNeighborIndex::KNearest(const Point& query, size_t k, double max_squared_distance,
                                    std::vector<size_t>& indices) const {
  std::vector<double> squared_distances;
  KNearest(query, k, max_squared_distance, indices, squared_distances);
}

void NearestNeighborIndex::KNearest(const Point& query, size_t k, double max_squared_distance,
                                    std::vector<size_t>& indices,
                                    std::vector<double>& squared_distances) const {
  indices.resize(k);
  squared_distances.resize(k);
  size_t found = tree_->kdtree.knnSearch(query.data(), k, indices.data(), squared_distances.data());
  while (found > 0 && squared_distances[found - 1] > max_squared_distance) --found;
  indices.resize(found);
  squared_distances.resize(found);
}

const Points& NearestNeighborIndex::points() const { return tree_->adaptor.points; }

}  // namespace boicp
