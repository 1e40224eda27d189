#pragma once
// Trajectory files: TUM ("timestamp tx ty tz qx qy qz qw" per line) and
// KITTI odometry (the 12 numbers of the row-major 3x4 per line). Both hold
// poses T_map_scan.

#include <iosfwd>
#include <string>
#include <vector>

#include "boicp/util/types.hpp"

namespace boicp {

/// One pose per line, `timestamps` in seconds (same length as `poses`).
/// Throws InputError when the lengths differ.
void WriteTumTrajectory(std::ostream& out, const std::vector<double>& timestamps,
                        const std::vector<Transform>& poses);

void WriteKittiTrajectory(std::ostream& out, const std::vector<Transform>& poses);

struct TimedPose {
  double timestamp = 0.0;
  Transform pose = Transform::Identity();
};

/// Reads a TUM trajectory; skips blank and '#' lines. Throws InputError
/// naming the file and line for anything that is not 8 numbers.
std::vector<TimedPose> ReadTumTrajectory(const std::string& path);

/// Reads a KITTI trajectory. Throws InputError naming the file and line for
/// anything that is not 12 numbers.
std::vector<Transform> ReadKittiTrajectory(const std::string& path);

}  // namespace boicp
