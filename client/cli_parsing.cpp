#include "cli_parsing.hpp"

#include <unistd.h>

#include <cmath>
#include <sstream>

#include "boicp/util/types.hpp"

namespace boicp::cli {

const char* const kSensorUpHelp =
    "X,Y,Z: the sensor's up in its own frame (0,-1,0 for depth cameras, 0,0,1 for LiDAR); "
    "steers the search for the map's up through the trajectory's poses";

std::optional<Eigen::Vector3d> ParseSensorUp(const std::string& text) {
  if (text.empty()) return std::nullopt;
  const Eigen::Vector3d up = ParseTriple(text, "--sensor-up");
  if (!(up.norm() > 0.0)) throw InputError("--sensor-up: must not be zero");
  return up;
}

Eigen::Vector3d ParseTriple(const std::string& text, const std::string& flag) {
  std::stringstream stream(text);
  std::string item;
  Eigen::Vector3d values;
  int count = 0;
  while (std::getline(stream, item, ',')) {
    try {
      size_t used = 0;
      const double value = item == "pi" ? (used = item.size(), M_PI) : std::stod(item, &used);
      if (used != item.size() || !std::isfinite(value) || count >= 3)
        throw std::invalid_argument(item);
      values[count++] = value;
    } catch (const std::exception&) {
      throw InputError(flag + ": expected three comma-separated numbers (or pi), got '" + text +
                       "'");
    }
  }
  if (count != 3) {
    throw InputError(flag + ": expected three comma-separated numbers (or pi), got '" + text + "'");
  }
  return values;
}

bool StderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

}  // namespace boicp::cli
