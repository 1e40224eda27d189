#pragma once
// Order statistics shared across core.

#include <algorithm>
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

}  // namespace boicp
