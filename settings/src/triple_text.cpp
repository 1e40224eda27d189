#include "boicp/settings/triple_text.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "boicp/util/types.hpp"

namespace boicp::settings {

Eigen::Vector3d ParseTriple(const std::string& text, const std::string& flag) {
  const std::string error =
      flag + ": expected three comma-separated numbers (or pi), got '" + text + "'";
  std::stringstream stream(text);
  std::string item;
  Eigen::Vector3d values;
  int count = 0;
  while (std::getline(stream, item, ',')) {
    try {
      size_t used = 0;
      const double value = item == "pi" ? (used = item.size(), M_PI) : std::stod(item, &used);
      if (used != item.size() || !std::isfinite(value) || count >= 3) {
        throw std::invalid_argument(item);
      }
      values[count++] = value;
    } catch (const std::exception&) {
      throw InputError(error);
    }
  }
  if (count != 3) throw InputError(error);
  return values;
}

namespace {

// The shortest of %.15g and %.17g that reads back as the same double.
std::string FormatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.15g", value);
  if (std::strtod(text, nullptr) != value) std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

}  // namespace

std::string FormatTriple(const Eigen::Vector3d& values) {
  return FormatNumber(values[0]) + "," + FormatNumber(values[1]) + "," + FormatNumber(values[2]);
}

}  // namespace boicp::settings
