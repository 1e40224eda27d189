#pragma once
// A read-only view of points held elsewhere, so that a caller's buffer (a
// numpy array, a mapped file) is read where it lies instead of being copied
// into Points first.

#include <cstddef>
#include <iterator>

#include "boicp/util/types.hpp"

namespace boicp {

static_assert(sizeof(Point) == 3 * sizeof(double), "Points are stored as packed x, y, z");

/// Points whose coordinates are rows of doubles: point i is (x, y, z) at
/// xyz[i * row_stride + 0, 1, 2], in metres. The storage must outlive the
/// view and must not change while it is read.
class PointSpan {
 public:
  /// Walks the points in order; each is read as a Point value.
  class Iterator {
   public:
    using iterator_category = std::input_iterator_tag;
    using value_type = Point;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = Point;

    Iterator(const PointSpan& span, size_t index) : span_(&span), index_(index) {}
    Point operator*() const { return (*span_)[index_]; }
    Iterator& operator++() {
      ++index_;
      return *this;
    }
    bool operator==(const Iterator& other) const { return index_ == other.index_; }
    bool operator!=(const Iterator& other) const { return index_ != other.index_; }

   private:
    const PointSpan* span_;
    size_t index_;
  };

  PointSpan() = default;
  /// A view of `points` (implicit, so every function taking a span takes Points).
  PointSpan(const Points& points)  // NOLINT(google-explicit-constructor)
      : xyz_(points.empty() ? nullptr : points.front().data()), size_(points.size()) {}
  /// A view of `size` rows of at least 3 doubles, `row_stride` >= 3 doubles apart.
  PointSpan(const double* xyz, size_t size, size_t row_stride)
      : xyz_(xyz), size_(size), row_stride_(row_stride) {}

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  Point operator[](size_t i) const {
    const double* row = xyz_ + i * row_stride_;
    return Point(row[0], row[1], row[2]);
  }
  Iterator begin() const { return Iterator(*this, 0); }
  Iterator end() const { return Iterator(*this, size_); }

  /// The points copied into a vector of their own.
  Points ToPoints() const {
    Points points;
    points.reserve(size_);
    for (size_t i = 0; i < size_; ++i) points.push_back((*this)[i]);
    return points;
  }

 private:
  const double* xyz_ = nullptr;
  size_t size_ = 0;
  size_t row_stride_ = 3;
};

}  // namespace boicp
