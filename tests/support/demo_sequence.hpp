#pragma once
// A generated drive along the synthetic street, so the daemon's demo and
// tests run on a machine without real data. Accuracy claims are never based
// on it.

#include <cstdint>
#include <string>
#include <vector>

#include "boicp/util/types.hpp"

namespace boicp::test {

struct GeneratedScan {
  std::string kitti_bytes;  // the scan as a KITTI .bin (float32 x y z 0 per point)
  Transform T_world_scan = Transform::Identity();
};

/// MakeSyntheticDrive's scans, encoded as KITTI .bin files.
std::vector<GeneratedScan> MakeDemoSequence(int num_scans, uint64_t seed);

/// Encodes points as a KITTI .bin (reflectance 0).
std::string EncodeKittiBin(const Points& points);

}  // namespace boicp::test
