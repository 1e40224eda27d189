#pragma once
// Clouds between numpy and the engine, copied only where the layout forces it:
// a float64 array whose rows hold x, y, z side by side is read where it lies,
// and Points go out as an array over their own memory.

#include <string>

#include <pybind11/numpy.h>

#include "boicp/util/point_span.hpp"
#include "boicp/util/types.hpp"

namespace boicp::python {

/// The rows of an (N, 3) float64 or float32 array as points for the engine.
/// A float64 array in native byte order whose three coordinates of a row are
/// adjacent (C order, or the first three columns of a wider C-order array) is
/// viewed in place; any other layout or type is copied once. Create and
/// destroy it with the GIL held; while the engine reads it, the array must
/// not change.
class ArrayPoints {
 public:
  /// Throws InputError naming `what` for another shape or type, or for a
  /// point that is not finite.
  ArrayPoints(const pybind11::array& array, const std::string& what);
  ArrayPoints(const ArrayPoints&) = delete;
  ArrayPoints& operator=(const ArrayPoints&) = delete;

  PointSpan span() const { return span_; }
  /// True when the points are read in the caller's array, not a copy.
  bool in_place() const { return copy_.empty() && !span_.empty(); }

 private:
  pybind11::array array_;  // keeps a viewed buffer alive
  Points copy_;
  PointSpan span_;
};

/// `points` as an (N, 3) float64 array that owns them (no copy).
pybind11::array_t<double> ArrayFromPoints(Points points);

/// A 4 x 4 array as a Transform. Throws InputError naming `what` unless it
/// is a rigid motion (RequireRigidTransform).
Transform TransformFromArray(const pybind11::array& array, const std::string& what);

}  // namespace boicp::python
