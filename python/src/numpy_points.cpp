#include "numpy_points.hpp"

#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp::python {
namespace py = pybind11;

namespace {

// Where a float64 array's rows can be read as they lie: three adjacent
// doubles a row, rows a whole number of doubles apart.
bool RowsReadableInPlace(const py::array& array) {
  constexpr py::ssize_t kDouble = sizeof(double);
  return py::isinstance<py::array_t<double>>(array) && array.strides(1) == kDouble &&
         array.strides(0) >= 3 * kDouble && array.strides(0) % kDouble == 0 &&
         reinterpret_cast<std::uintptr_t>(array.data()) % alignof(double) == 0;
}

void RequireFinite(PointSpan points, const std::string& what) {
  size_t not_finite = 0;
  for (const Point& p : points) not_finite += !p.allFinite();
  if (not_finite > 0) {
    throw InputError(what + ": " + std::to_string(not_finite) + " of " +
                     std::to_string(points.size()) +
                     " points are not finite; keep the finite ones "
                     "(points[numpy.isfinite(points).all(axis=1)])");
  }
}

}  // namespace

ArrayPoints::ArrayPoints(const py::array& array, const std::string& what) : array_(array) {
  if (array.ndim() != 2 || array.shape(1) != 3) {
    throw InputError(what + ": expected an (N, 3) array of points, got shape " +
                     py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                                 array.shape(), array.shape() + array.ndim()))))
                         .cast<std::string>());
  }
  const char kind = array.dtype().kind();
  const py::ssize_t size = array.dtype().itemsize();
  if (kind != 'f' || (size != 8 && size != 4)) {
    throw InputError(what + ": expected float64 or float32 points, got " +
                     py::str(array.dtype()).cast<std::string>());
  }
  const auto rows = static_cast<size_t>(array.shape(0));
  if (RowsReadableInPlace(array)) {
    span_ = PointSpan(static_cast<const double*>(array.data()), rows,
                      static_cast<size_t>(array.strides(0)) / sizeof(double));
  } else {
    // The converted array must outlive `cells`, which points into it;
    // unchecked<> honours its strides, so views and Fortran order read as they are.
    const py::array_t<double, py::array::forcecast> converted(array);
    const auto cells = converted.unchecked<2>();
    copy_.resize(rows);
    for (size_t i = 0; i < rows; ++i) {
      const auto r = static_cast<py::ssize_t>(i);
      copy_[i] = Point(cells(r, 0), cells(r, 1), cells(r, 2));
    }
    span_ = copy_;
  }
  RequireFinite(span_, what);
}

py::array_t<double> ArrayFromPoints(Points points) {
  auto owned = std::make_unique<Points>(std::move(points));
  const auto rows = static_cast<py::ssize_t>(owned->size());
  const double* xyz = owned->empty() ? nullptr : owned->front().data();
  const py::capsule free_when_done(owned.get(), [](void* p) { delete static_cast<Points*>(p); });
  owned.release();  // the capsule owns the points now
  constexpr auto kRow = static_cast<py::ssize_t>(sizeof(Point));
  return py::array_t<double>({rows, py::ssize_t{3}}, {kRow, py::ssize_t{sizeof(double)}}, xyz,
                             free_when_done);
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
