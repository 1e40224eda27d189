#pragma once
// Basic geometric types shared by every boicp module.
//
// Frame convention everywhere: a transform named T (or T_target_source) maps a
// point from the source frame into the target frame, p_target = T * p_source.
// Units are metres and radians.

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace boicp {

using Point = Eigen::Vector3d;
using Points = std::vector<Point>;
using Transform = Eigen::Matrix4d;  // homogeneous, T_target_source

/// Thrown for bad user input (missing file, malformed data, invalid config).
/// The message is one line that names the file or field and the problem.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Thrown when work would need more memory than its limit allows. The
/// message names the limit, what was needed and what to change.
class LimitExceeded : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Applies T to every point: returns { T * p }.
Points TransformPoints(const Transform& T, const Points& points);

/// Rotation angle of T's rotation part, in radians, in [0, pi].
double RotationAngle(const Transform& T);

/// Euclidean norm of T's translation part, in metres.
double TranslationNorm(const Transform& T);

}  // namespace boicp

namespace boicp {

/// Thrown when a caller's stop request ends a long computation early.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

}  // namespace boicp
