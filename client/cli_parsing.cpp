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

bool StderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

}  // namespace boicp::cli
