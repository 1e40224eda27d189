#include "numpy_points.hpp"

#include <cmath>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp::python {
namespace py = pybind11;

namespace {

template <typename Scalar>
Points ReadRows(const py::array& array, const std::string& what) {
  // unchecked<> honours the array's strides, so views and Fortran order read as they are.
  const auto rows = py::array_t<Scalar, py::array::forcecast>(array).template unchecked<2>();
  Points points(static_cast<size_t>(rows.shape(0)));
  size_t not_finite = 0;
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    Point& p = points[static_cast<size_t>(i)];
    p = Point(rows(i, 0), rows(i, 1), rows(i, 2));
    not_finite += !p.allFinite();
  }
  if (not_finite > 0) {
    throw InputError(what + ": " + std::to_string(not_finite) + " of " +
                     std::to_string(points.size()) +
                     " points are not finite; keep the finite ones "
                     "(points[numpy.isfinite(points).all(axis=1)])");
  }
  return points;
}

}  // namespace

Points PointsFromArray(const py::array& array, const std::string& what) {
  if (array.ndim() != 2 || array.shape(1) != 3) {
    throw InputError(what + ": expected an (N, 3) array of points, got shape " +
                     py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                                 array.shape(), array.shape() + array.ndim()))))
                         .cast<std::string>());
  }
  if (array.dtype().is(py::dtype::of<double>())) return ReadRows<double>(array, what);
  if (array.dtype().is(py::dtype::of<float>())) return ReadRows<float>(array, what);
  throw InputError(what + ": expected float64 or float32 points, got " +
                   py::str(array.dtype()).cast<std::string>());
}

py::array_t<double> ArrayFromPoints(const Points& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  auto rows = out.mutable_unchecked<2>();
  for (size_t i = 0; i < points.size(); ++i) {
    for (py::ssize_t j = 0; j < 3; ++j) rows(static_cast<py::ssize_t>(i), j) = points[i][j];
  }
  return out;
}

Transform TransformFromArray(const py::array& array, const std::string& what) {
  if (array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4) {
    throw InputError(what + ": expected a 4 x 4 matrix");
  }
  const auto m = py::array_t<double, py::array::forcecast>(array).unchecked<2>();
  Transform T;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) T(i, j) = m(i, j);
  }
  if (!T.allFinite()) throw InputError(what + ": not finite");
  RequireRigidTransform(what, T);
  return T;
}

}  // namespace boicp::python
