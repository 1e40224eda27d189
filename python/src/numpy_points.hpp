#pragma once
// Clouds between numpy and the engine: an (N, 3) float64 or float32 array
// is read into Points (one copy: Points owns its memory), and Points go out
// as a new (N, 3) float64 array.

#include <string>

#include <pybind11/numpy.h>

#include "boicp/util/types.hpp"

namespace boicp::python {

/// The rows of `array`, an (N, 3) float64 or float32 array in any memory
/// layout. Throws InputError naming `what` for another shape or type, or
/// for a point that is not finite.
Points PointsFromArray(const pybind11::array& array, const std::string& what);

/// `points` as a new (N, 3) float64 array.
pybind11::array_t<double> ArrayFromPoints(const Points& points);

/// A 4 x 4 array as a Transform. Throws InputError naming `what` unless it
/// is a rigid motion (RequireRigidTransform).
Transform TransformFromArray(const pybind11::array& array, const std::string& what);

}  // namespace boicp::python
