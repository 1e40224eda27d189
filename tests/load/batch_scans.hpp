#pragma once
// The scans the load clients upload: windows of consecutive scans of one
// generated drive, each thinned to a random subset of its points, so every
// batch is new bytes for the daemon (nothing is deduplicated) yet still a
// drive the registration can follow.

#include <cstdint>
#include <string>
#include <vector>

#include "boicp/io/synthetic_scene.hpp"

namespace boicp::load {

class BatchScans {
 public:
  /// Generates a drive of `drive_scans` scans from `seed`. Read-only
  /// afterwards, so clients on several threads may share one.
  BatchScans(int drive_scans, uint64_t seed);

  /// KITTI .bin bytes of `count` consecutive scans starting at a random
  /// index, each reduced to `points` random points (all when it has fewer).
  /// Reproducible for a given `seed`.
  std::vector<std::string> Make(int count, int points, uint64_t seed) const;

 private:
  std::vector<SyntheticScan> drive_;
};

/// A well-mixed 64-bit seed from a base seed and two non-negative indices
/// (SplitMix64), so that every client, batch and phase draws its own stream.
uint64_t MixSeed(uint64_t base, int a, int b = 0);

}  // namespace boicp::load
