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

/// SimulateScan for a spinning sensor whose sweep starts at T_world_start:
/// a point at azimuth a (radians from -pi) is measured at the sweep's
/// fraction (a + pi) / 2 pi, from the sensor moved by that fraction of
/// `travel` (metres, world frame) and turned by that fraction of `turn`
/// (radians about its z), and kept in that moved sensor's frame, as a scan
/// that is not de-skewed keeps it.
Points SimulateSweptScan(const Points& world, const Transform& T_world_start,
                         const Eigen::Vector3d& travel, double turn, double range,
                         double noise_sigma, uint64_t seed);

/// Pose with yaw (radians, about z) and translation (metres).
Transform PoseFromYawTranslation(double yaw, const Eigen::Vector3d& translation);

/// One scan of a generated drive: points in the sensor frame and the true pose.
struct SyntheticScan {
  Points points;
  Transform T_world_scan = Transform::Identity();
};

/// Surface samples (world frame) of the street's continuation number
/// `segment` >= 1: the 80 m beyond MakeSyntheticStreet's end (x = 40 m) for
/// segment 1, the 80 m beyond that for segment 2, and so on. Facades, cars,
/// poles and trees are placed at random from (seed, segment), so every
/// segment differs and is reproducible.
Points MakeStreetSegment(uint64_t seed, int segment, double density = 40.0);

/// A generated drive along the street, which extends (MakeStreetSegment) as
/// far as the drive goes: scans 2 m apart with a gentle weave and a sensor
/// that turns 0.04 rad per scan, seen by a 35 m-range sensor 1.8 m above the
/// ground with 2 cm noise. With `loop`, the second half of the drive comes
/// back in the other lane and ends beside the start. Scans are generated one
/// at a time, so a long drive needs memory for its street only.
///
/// With `drift`, the drive is logged as a throttled LiDAR log is: scans
/// 0.5-7 m apart and turns of up to 0.75 rad between them, drawn from the
/// seed, and each scan swept over 0.1 s while the sensor moves 1 m and turns
/// 0.02 rad, without de-skewing. Chained registration of such scans drifts
/// as a LiDAR odometry does.
class SyntheticDrive {
 public:
  /// Precondition: num_scans >= 0. Builds the street the drive sees.
  SyntheticDrive(int num_scans, uint64_t seed, bool loop = false, bool drift = false);

  int size() const { return num_scans_; }

  /// True T_world_scan of scan `index` in [0, size()); with `drift`, where
  /// the sensor is halfway through the scan's sweep.
  Transform Pose(int index) const;

  /// Scan `index` in [0, size()): the same points for the same seed, and for
  /// a scan of the outbound leg whatever the drive's length.
  SyntheticScan Scan(int index) const;

 private:
  int num_scans_;
  uint64_t seed_;
  bool loop_;
  bool drift_;
  std::vector<double> station_x_;  // metres along the street, one per outbound scan
  std::vector<double> yaw_;        // radians, one per scan
  std::vector<Points> segments_;   // [0] = MakeSyntheticStreet, then MakeStreetSegment(k)
};

/// Every scan of SyntheticDrive(num_scans, seed, loop), in memory at once.
std::vector<SyntheticScan> MakeSyntheticDrive(int num_scans, uint64_t seed, bool loop = false,
                                              bool drift = false);

}  // namespace boicp
