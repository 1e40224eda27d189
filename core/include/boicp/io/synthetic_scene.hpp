#pragma once
// A generated street-like scene and simulated scans of it, for unit tests and
// the demo that must run on a machine without real data. Accuracy claims are
// never based on these.

#include <cstdint>
#include <vector>

#include "boicp/util/types.hpp"

namespace boicp {

/// Surface samples (metres, world frame) of an asymmetric street: ground,
/// building facades with gaps, poles and parked boxes. About `density`
/// points per square metre; reproducible for a given seed.
Points MakeSyntheticStreet(uint64_t seed, double density = 40.0);

/// The points of `world` within `range` metres of the sensor at
/// T_world_sensor, expressed in the sensor frame, with isotropic Gaussian
/// noise of `noise_sigma` metres. Reproducible for a given seed.
Points SimulateScan(const Points& world, const Transform& T_world_sensor, double range,
                    double noise_sigma, uint64_t seed);

/// Pose with yaw (radians, about z) and translation (metres).
Transform PoseFromYawTranslation(double yaw, const Eigen::Vector3d& translation);

/// One scan of a generated drive: points in the sensor frame and the true pose.
struct SyntheticScan {
  Points points;
  Transform T_world_scan = Transform::Identity();
};

/// `num_scans` scans of the street, 2 m apart with a gentle weave and turn,
/// seen by a 35 m-range sensor 1.8 m above the ground with 2 cm noise.
/// Reproducible for a given seed.
std::vector<SyntheticScan> MakeSyntheticDrive(int num_scans, uint64_t seed);

}  // namespace boicp
