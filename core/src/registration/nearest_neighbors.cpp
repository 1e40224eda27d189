#include "boicp/registration/nearest_neighbors.hpp"

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

using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>,
                                        PointsAdaptor, 3, size_t>;

}  // namespace

struct NearestNeighborIndex::Tree {
  explicit Tree(Points pts)
      : adaptor{std::move(pts)},
        kdtree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}
  PointsAdaptor adaptor;
  KdTree kdtree;
};

NearestNeighborIndex::NearestNeighborIndex(Points points)
    : tree_(std::make_unique<Tree>(std::move(points))) {
  if (tree_->adaptor.points.empty())
    throw InputError("nearest-neighbour index: empty target cloud");
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
  const double hint_squared = (tree_->adaptor.points[hint] - query).squaredNorm();
  if (!(hint_squared < max_squared_distance)) {
    return Nearest(query, max_squared_distance, index, squared_distance);
  }
  BoundedNearestResult result(hint_squared, hint);
  tree_->kdtree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  index = result.index();
  squared_distance = result.worstDist();
  return true;
}

void NearestNeighborIndex::KNearest(const Point& query, size_t k, double max_squared_distance,
                                    std::vector<size_t>& indices) const {
  indices.resize(k);
  std::vector<double> squared_distances(k);
  size_t found = tree_->kdtree.knnSearch(query.data(), k, indices.data(), squared_distances.data());
  while (found > 0 && squared_distances[found - 1] > max_squared_distance) --found;
  indices.resize(found);
}

const Points& NearestNeighborIndex::points() const { return tree_->adaptor.points; }

}  // namespace boicp
