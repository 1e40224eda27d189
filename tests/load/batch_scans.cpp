#include "batch_scans.hpp"

#include <algorithm>
#include <iterator>
#include <random>
#include <stdexcept>

#include "../support/demo_sequence.hpp"
#include "boicp/mapping/map_pairs.hpp"

namespace boicp::load {

uint64_t MixSeed(uint64_t base, int a, int b) {
  // Core's per-pair seed is exactly a SplitMix64 mix of a seed and two small
  // indices; reusing it keeps one copy of the mixer.
  return PairSeed(base, PairIndex{a, b});
}

BatchScans::BatchScans(int drive_scans, uint64_t seed)
    : drive_(MakeSyntheticDrive(drive_scans, seed)) {}

std::vector<std::string> BatchScans::Make(int count, int points, uint64_t seed) const {
  if (count < 1 || static_cast<size_t>(count) > drive_.size()) {
    throw std::invalid_argument("BatchScans::Make: count must be in 1..drive size");
  }
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> first_index(0, drive_.size() - static_cast<size_t>(count));
  const size_t first = first_index(rng);
  std::vector<std::string> scans;
  for (size_t i = first; i < first + static_cast<size_t>(count); ++i) {
    Points subset;
    std::sample(drive_[i].points.begin(), drive_[i].points.end(), std::back_inserter(subset),
                static_cast<size_t>(points), rng);
    scans.push_back(test::EncodeKittiBin(subset));
  }
  return scans;
}

}  // namespace boicp::load
