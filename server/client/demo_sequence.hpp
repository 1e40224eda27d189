#pragma once
// A generated drive along the synthetic street, so the daemon's demo and
// tests run on a machine without real data. Accuracy claims are never based
// on it.

#include <cstdint>
#include <string>
#include <vector>

#include "boicp/types.hpp"

namespace boicp::client {

struct GeneratedScan {
  std::string kitti_bytes;  // the scan as a KITTI .bin (float32 x y z 0 per point)
  Transform T_world_scan = Transform::Identity();
};

/// `num_scans` scans, 2 m apart along the street with a gentle weave and
/// turn, seen by a 35 m-range sensor 1.8 m above the ground. Reproducible
/// for a given seed.
std::vector<GeneratedScan> MakeDemoSequence(int num_scans, uint64_t seed);

/// Encodes points as a KITTI .bin (reflectance 0).
std::string EncodeKittiBin(const Points& points);

}  // namespace boicp::client
