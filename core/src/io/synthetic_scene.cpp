#include "boicp/io/synthetic_scene.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace boicp {
namespace {

// Uniform samples on the axis-aligned rectangle spanned by `corner` and the
// two edge vectors.
void SampleRectangle(const Point& corner, const Point& edge_a, const Point& edge_b, double density,
                     std::mt19937_64& rng, Points& out) {
  const double area = edge_a.cross(edge_b).norm();
  const auto count = static_cast<size_t>(area * density);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (size_t i = 0; i < count; ++i)
    out.push_back(corner + unit(rng) * edge_a + unit(rng) * edge_b);
}

// A closed box as its five visible faces (no bottom).
void SampleBox(const Point& min_corner, const Point& size, double density, std::mt19937_64& rng,
               Points& out) {
  const Point dx(size.x(), 0, 0), dy(0, size.y(), 0), dz(0, 0, size.z());
  SampleRectangle(min_corner, dx, dz, density, rng, out);
  SampleRectangle(min_corner + dy, dx, dz, density, rng, out);
  SampleRectangle(min_corner, dy, dz, density, rng, out);
  SampleRectangle(min_corner + dx, dy, dz, density, rng, out);
  SampleRectangle(min_corner + dz, dx, dy, density, rng, out);
}

void SamplePole(const Point& base, double radius, double height, double density,
                std::mt19937_64& rng, Points& out) {
  const auto count = static_cast<size_t>(2.0 * M_PI * radius * height * density);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (size_t i = 0; i < count; ++i) {
    const double angle = 2.0 * M_PI * unit(rng);
    out.push_back(base +
                  Point(radius * std::cos(angle), radius * std::sin(angle), height * unit(rng)));
  }
}

// The street: MakeSyntheticStreet spans x in [-40, 40] m, segment k >= 1
// spans [40 + 80 (k - 1), 40 + 80 k].
constexpr double kStreetEnd = 40.0;
constexpr double kSegmentLength = 80.0;
constexpr double kScanRange = 35.0;   // metres
constexpr double kScanNoise = 0.02;   // metres, per coordinate
constexpr double kScanSpacing = 2.0;  // metres along the street
constexpr double kReturnLane = -3.0;  // metres, y of a loop's way back
constexpr double kFirstScanX = -7.0;  // metres

double SegmentStart(int segment) { return kStreetEnd + kSegmentLength * (segment - 1); }

// SplitMix64's finaliser: independent-looking seeds from (seed, index).
uint64_t MixSeed(uint64_t seed, uint64_t index) {
  uint64_t z = seed + 0x9E3779B97F4A7C15ull * (index + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Facade blocks of random length, height and setback with random gaps along
// one side (side = +1 left, -1 right) of [x_begin, x_end].
void SampleFacades(double x_begin, double x_end, double side, double density, std::mt19937_64& rng,
                   Points& out) {
  std::uniform_real_distribution<double> gap(0.0, 6.0), length(8.0, 25.0), setback(8.0, 10.0),
      height(5.0, 14.0);
  double x = x_begin + gap(rng);
  while (x_end - x >= 3.0) {
    const double block = std::min(length(rng), x_end - x);
    SampleRectangle(Point(x, side * setback(rng), 0), Point(block, 0, 0), Point(0, 0, height(rng)),
                    density, rng, out);
    x += block + gap(rng);
  }
}

}  // namespace

Points MakeStreetSegment(uint64_t seed, int segment, double density) {
  if (segment < 1) throw std::invalid_argument("MakeStreetSegment: segment must be >= 1");
  std::mt19937_64 rng(MixSeed(seed, static_cast<uint64_t>(segment)));
  const double x0 = SegmentStart(segment);
  const double x1 = x0 + kSegmentLength;
  Points world;
  SampleRectangle(Point(x0, -12, 0), Point(kSegmentLength, 0, 0), Point(0, 24, 0), density / 8, rng,
                  world);
  SampleFacades(x0, x1, +1.0, density, rng, world);
  SampleFacades(x0, x1, -1.0, density, rng, world);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int cars = 2 + static_cast<int>(rng() % 3);
  for (int c = 0; c < cars; ++c) {
    const double x = x0 + 2.0 + 73.0 * unit(rng);
    const double y = unit(rng) < 0.5 ? 4.8 + 0.7 * unit(rng) : -7.0 + 0.8 * unit(rng);
    SampleBox(Point(x, y, 0),
              Point(3.8 + 1.0 * unit(rng), 1.7 + 0.2 * unit(rng), 1.4 + 0.4 * unit(rng)), density,
              rng, world);
  }
  for (double x = x0 + 9.5 * unit(rng); x < x1; x += 9.5)
    SamplePole(Point(x, 6.8, 0), 0.15, 6, density, rng, world);
  for (double x = x0 + 12.0 * unit(rng); x < x1; x += 12.0)
    SamplePole(Point(x, -6.8, 0), 0.4, 3, density, rng, world);
  return world;
}

Points MakeSyntheticStreet(uint64_t seed, double density) {
  std::mt19937_64 rng(seed);
  Points world;
  // Ground is sparser than structure, as on a real LiDAR scan far from the car.
  SampleRectangle(Point(-40, -12, 0), Point(80, 0, 0), Point(0, 24, 0), density / 8, rng, world);
  // Facades along both sides, with gaps at different places so the street is
  // not symmetric under a half turn.
  SampleRectangle(Point(-40, 8, 0), Point(25, 0, 0), Point(0, 0, 9), density, rng, world);
  SampleRectangle(Point(-10, 9, 0), Point(18, 0, 0), Point(0, 0, 14), density, rng, world);
  SampleRectangle(Point(14, 8, 0), Point(26, 0, 0), Point(0, 0, 6), density, rng, world);
  SampleRectangle(Point(-40, -9, 0), Point(12, 0, 0), Point(0, 0, 7), density, rng, world);
  SampleRectangle(Point(-22, -8, 0), Point(30, 0, 0), Point(0, 0, 11), density, rng, world);
  SampleRectangle(Point(18, -10, 0), Point(22, 0, 0), Point(0, 0, 5), density, rng, world);
  SampleRectangle(Point(-22, -8, 0), Point(0, -1, 0), Point(0, 0, 11), density, rng, world);
  // Parked cars and a kiosk.
  SampleBox(Point(-15, 5, 0), Point(4.5, 1.8, 1.5), density, rng, world);
  SampleBox(Point(-6, 5.2, 0), Point(4.2, 1.8, 1.6), density, rng, world);
  SampleBox(Point(9, -6.5, 0), Point(4.8, 1.9, 1.7), density, rng, world);
  SampleBox(Point(25, 3, 0), Point(3, 3, 2.5), density, rng, world);
  // Street lights and trees on one side only.
  for (double x = -32; x <= 32; x += 9.5)
    SamplePole(Point(x, 6.8, 0), 0.15, 6, density, rng, world);
  for (double x = -28; x <= 20; x += 12) SamplePole(Point(x, -6.8, 0), 0.4, 3, density, rng, world);
  return world;
}

Points SimulateScan(const Points& world, const Transform& T_world_sensor, double range,
                    double noise_sigma, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma);
  const Transform T_sensor_world = T_world_sensor.inverse();
  const Eigen::Matrix3d R = T_sensor_world.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_sensor_world.topRightCorner<3, 1>();
  Points scan;
  for (const Point& p : world) {
    const Point q = R * p + t;
    if (q.norm() > range) continue;
    scan.push_back(noise_sigma > 0 ? Point(q + Point(noise(rng), noise(rng), noise(rng))) : q);
  }
  return scan;
}

Transform PoseFromYawTranslation(double yaw, const Eigen::Vector3d& translation) {
  Transform T = Transform::Identity();
  T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.topRightCorner<3, 1>() = translation;
  return T;
}

namespace {

// A drifting drive's sweep: 0.1 s at 10 m/s, turning at 0.2 rad/s.
constexpr double kSweepTravel = 1.0;  // metres
constexpr double kSweepTurn = 0.02;   // radians

}  // namespace

Points SimulateSweptScan(const Points& world, const Transform& T_world_start,
                         const Eigen::Vector3d& travel, double turn, double range,
                         double noise_sigma, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma);
  const Transform T_start_world = T_world_start.inverse();
  Points scan;
  for (const Point& p : world) {
    const Point at_start =
        T_start_world.topLeftCorner<3, 3>() * p + T_start_world.topRightCorner<3, 1>();
    if (at_start.norm() > range + travel.norm()) continue;
    const double fraction = (std::atan2(at_start.y(), at_start.x()) + M_PI) / (2.0 * M_PI);
    Transform T_world_now = T_world_start;
    T_world_now.topLeftCorner<3, 3>() *=
        Eigen::AngleAxisd(fraction * turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_world_now.topRightCorner<3, 1>() += fraction * travel;
    const Point q =
        T_world_now.topLeftCorner<3, 3>().transpose() * (p - T_world_now.topRightCorner<3, 1>());
    if (q.norm() > range) continue;
    scan.push_back(noise_sigma > 0 ? Point(q + Point(noise(rng), noise(rng), noise(rng))) : q);
  }
  return scan;
}

SyntheticDrive::SyntheticDrive(int num_scans, uint64_t seed, bool loop, bool drift)
    : num_scans_(std::max(num_scans, 0)), seed_(seed), loop_(loop), drift_(drift) {
  // A loop's outbound leg is its first half, rounded up; the way back runs
  // the same stations in reverse order in the other lane.
  const int outbound = loop_ ? (num_scans_ + 1) / 2 : num_scans_;
  std::mt19937_64 rng(MixSeed(seed, 0xD81F7));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double x = kFirstScanX, yaw = 0.0;
  for (int i = 0; i < num_scans_; ++i) {
    if (!drift_) {
      if (i < outbound) station_x_.push_back(kFirstScanX + kScanSpacing * i);
      yaw_.push_back(0.04 * i);
      continue;
    }
    if (i > 0) {
      // Mostly 0.5-4 m on, one step in ten 4-7 m; mostly a small turn, one in
      // twenty a sharp one.
      const bool long_step = unit(rng) < 0.1;
      const double step = long_step ? 4.0 + 3.0 * unit(rng) : 0.5 + 3.5 * unit(rng);
      const double turn = -0.05 + 0.2 * unit(rng);
      const bool sharp_turn = unit(rng) < 0.05;
      const double sharp = sharp_turn ? 0.35 + 0.25 * unit(rng) : 0.0;
      if (i < outbound) x += step;
      yaw += turn + sharp;
    }
    if (i < outbound) station_x_.push_back(x);
    yaw_.push_back(yaw);
  }
  segments_.push_back(MakeSyntheticStreet(seed));
  double farthest = kFirstScanX;
  for (const double station : station_x_) farthest = std::max(farthest, station);
  const int last_segment =
      static_cast<int>(std::ceil((farthest + kScanRange - kStreetEnd) / kSegmentLength));
  for (int k = 1; k <= last_segment; ++k) segments_.push_back(MakeStreetSegment(seed, k));
}

Transform SyntheticDrive::Pose(int index) const {
  const int outbound = static_cast<int>(station_x_.size());
  const bool returning = index >= outbound;
  const int station = returning ? 2 * outbound - 1 - index : index;
  const double lane = returning ? kReturnLane : 0.0;
  return PoseFromYawTranslation(
      yaw_.at(static_cast<size_t>(index)),
      {station_x_.at(static_cast<size_t>(station)), lane + 0.4 * std::sin(0.7 * index), 1.8});
}

SyntheticScan SyntheticDrive::Scan(int index) const {
  if (index < 0 || index >= num_scans_) throw std::out_of_range("SyntheticDrive::Scan: index");
  SyntheticScan scan;
  scan.T_world_scan = Pose(index);
  const bool returning = index >= static_cast<int>(station_x_.size());
  const Eigen::Vector3d travel(returning ? -kSweepTravel : kSweepTravel, 0.0, 0.0);
  // The true pose is the sweep's middle, where a rigid fit of the whole sweep
  // lands; the sweep starts half its motion before it.
  Transform T_world_start = scan.T_world_scan;
  T_world_start.topLeftCorner<3, 3>() *=
      Eigen::AngleAxisd(-0.5 * kSweepTurn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_start.topRightCorner<3, 1>() -= 0.5 * travel;
  const auto simulate = [&](const Points& world, uint64_t seed) {
    return drift_ ? SimulateSweptScan(world, T_world_start, travel, kSweepTurn, kScanRange,
                                      kScanNoise, seed)
                  : SimulateScan(world, scan.T_world_scan, kScanRange, kScanNoise, seed);
  };
  const uint64_t scan_seed = seed_ + 100 + static_cast<uint64_t>(index);
  scan.points = simulate(segments_[0], scan_seed);
  const double x = scan.T_world_scan(0, 3);
  const double reach = kScanRange + (drift_ ? kSweepTravel : 0.0);
  for (size_t k = 1; k < segments_.size(); ++k) {
    const double x0 = SegmentStart(static_cast<int>(k));
    if (x + reach < x0 || x - reach > x0 + kSegmentLength) continue;
    const Points seen = simulate(segments_[k], MixSeed(scan_seed, k));
    scan.points.insert(scan.points.end(), seen.begin(), seen.end());
  }
  return scan;
}

std::vector<SyntheticScan> MakeSyntheticDrive(int num_scans, uint64_t seed, bool loop, bool drift) {
  const SyntheticDrive drive(num_scans, seed, loop, drift);
  std::vector<SyntheticScan> scans;
  scans.reserve(static_cast<size_t>(drive.size()));
  for (int i = 0; i < drive.size(); ++i) scans.push_back(drive.Scan(i));
  return scans;
}

}  // namespace boicp
