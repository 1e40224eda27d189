#include "boicp/io/synthetic_scene.hpp"

#include <cmath>
#include <random>

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

}  // namespace

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

std::vector<SyntheticScan> MakeSyntheticDrive(int num_scans, uint64_t seed) {
  const Points world = MakeSyntheticStreet(seed);
  std::vector<SyntheticScan> scans;
  for (int i = 0; i < num_scans; ++i) {
    SyntheticScan scan;
    scan.T_world_scan =
        PoseFromYawTranslation(0.04 * i, {-7.0 + 2.0 * i, 0.4 * std::sin(0.7 * i), 1.8});
    scan.points =
        SimulateScan(world, scan.T_world_scan, 35.0, 0.02, seed + 100 + static_cast<uint64_t>(i));
    scans.push_back(std::move(scan));
  }
  return scans;
}

}  // namespace boicp
