#pragma once
// Order statistics shared by core, the bench and the tests.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace boicp {

/// The q-quantile (0 <= q <= 1) of `values`, taken as the element of rank
/// floor(q * (n - 1)) without interpolation. Precondition: `values` is not empty.
inline double Percentile(std::vector<double> values, double q) {
  const size_t k = static_cast<size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/// The median of `values`: the middle element, or the mean of the two
/// middle ones; NaN when `values` is empty.
inline double Median(std::vector<double> values) {
  if (values.empty()) return NAN;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(),
                                          values.begin() + static_cast<std::ptrdiff_t>(mid)));
}

}  // namespace boicp
