#include "demo_sequence.hpp"

#include <cstring>

#include "boicp/io/synthetic_scene.hpp"

namespace boicp::test {

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
  std::vector<GeneratedScan> scans;
  for (const SyntheticScan& scan : MakeSyntheticDrive(num_scans, seed)) {
    scans.push_back({EncodeKittiBin(scan.points), scan.T_world_scan});
  }
  return scans;
}

}  // namespace boicp::test
