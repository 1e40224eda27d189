#include "demo_sequence.hpp"

#include <cmath>
#include <cstring>

#include "boicp/synthetic_scene.hpp"

namespace boicp::client {

std::string EncodeKittiBin(const Points& points) {
  std::string bytes;
  bytes.reserve(points.size() * 16);
  auto append = [&bytes](float value) {
    uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof(bits));
    for (int shift = 0; shift < 32; shift += 8) {
      bytes.push_back(static_cast<char>((bits >> shift) & 0xff));
    }
  };
  for (const Point& p : points) {
    append(static_cast<float>(p.x()));
    append(static_cast<float>(p.y()));
    append(static_cast<float>(p.z()));
    append(0.0f);
  }
  return bytes;
}

std::vector<GeneratedScan> MakeDemoSequence(int num_scans, uint64_t seed) {
  const Points world = MakeSyntheticStreet(seed);
  std::vector<GeneratedScan> scans;
  for (int i = 0; i < num_scans; ++i) {
    GeneratedScan scan;
    const double yaw = 0.04 * i;
    scan.T_world_scan = PoseFromYawTranslation(yaw, {-7.0 + 2.0 * i, 0.4 * std::sin(0.7 * i), 1.8});
    scan.kitti_bytes = EncodeKittiBin(
        SimulateScan(world, scan.T_world_scan, 35.0, 0.02, seed + 100 + static_cast<uint64_t>(i)));
    scans.push_back(std::move(scan));
  }
  return scans;
}

}  // namespace boicp::client
