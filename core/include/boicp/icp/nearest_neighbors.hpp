#pragma once
// A kd-tree over a fixed target cloud, built once and queried many times:
// BO-ICP evaluates hundreds of ICP runs against one target, so the tree must
// outlive any single run (Open3D's RegistrationICP rebuilds it per call).

#include <memory>

#include "boicp/util/types.hpp"

namespace boicp {

class NearestNeighborIndex {
 public:
  /// Length of a point's neighbour list (see the constructor).
  static constexpr size_t kNeighbourListSize = 16;
  /// Leaf size for a tree that is queried about as often as it has points.
  static constexpr size_t kDefaultLeafSize = 10;
  /// Leaf size for a tree that is queried far less often than it has points
  /// (a few thousand samples of a whole scan): it builds in a fraction of the
  /// default's time, and those few searches cost little more.
  static constexpr size_t kFewQueriesLeafSize = 64;

  /// Builds the tree over a copy of `points`. With `neighbour_lists`, also
  /// lists each point's kNeighbourListSize nearest other points, which let
  /// NearestWithHint answer most queries from the hint's list instead of the
  /// tree; building them costs one tree search a point, so they pay off on a
  /// target that hundreds of ICP runs query. `leaf_size` is the most points
  /// a tree leaf holds: larger leaves build faster and search slower, and
  /// every search gives the same answer whatever its value. Preconditions:
  /// points non-empty, leaf_size >= 1.
  explicit NearestNeighborIndex(Points points, bool neighbour_lists = false,
                                size_t leaf_size = kDefaultLeafSize);
  ~NearestNeighborIndex();
  NearestNeighborIndex(NearestNeighborIndex&&) noexcept;
  NearestNeighborIndex& operator=(NearestNeighborIndex&&) noexcept;

  /// Nearest target point to `query` within sqrt(max_squared_distance) metres.
  /// Returns false when there is none; otherwise sets index and squared distance.
  /// Thread-safe for concurrent queries; allocates nothing.
  bool Nearest(const Point& query, double max_squared_distance, size_t& index,
               double& squared_distance) const;

  /// The same, given a target point `hint` (an index into points()) known to
  /// be close, such as the previous ICP iteration's match: its distance
  /// bounds the search from the start, so far fewer tree cells are visited.
  /// With neighbour lists the tree is not searched at all when the hint's
  /// list provably holds the answer. Same answer as Nearest except that among
  /// points at exactly the hint's distance the hint is returned.
  /// Precondition: hint < size().
  bool NearestWithHint(const Point& query, size_t hint, double max_squared_distance, size_t& index,
                       double& squared_distance) const;

  /// Up to `k` target points nearest to `query` (nearest first) within
  /// sqrt(max_squared_distance) metres: their indices go to `indices`, which
  /// is resized to their number. Thread-safe for concurrent queries.
  void KNearest(const Point& query, size_t k, double max_squared_distance,
                std::vector<size_t>& indices) const;
  /// The same, with their squared distances (metres^2) in `squared_distances`.
  void KNearest(const Point& query, size_t k, double max_squared_distance,
                std::vector<size_t>& indices, std::vector<double>& squared_distances) const;

  const Points& points() const;
  size_t size() const { return points().size(); }

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

}  // namespace boicp
