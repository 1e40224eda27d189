#include "boicp/mapping/map_pairs.hpp"

#include <algorithm>
#include <numeric>
#include <set>
#include <string>
#include <utility>

#include "boicp/util/types.hpp"

namespace boicp {
namespace {

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

int FindRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

}  // namespace

std::string PairName(const PairIndex& p) {
  return std::to_string(p.source) + "->" + std::to_string(p.target);
}

std::vector<PairIndex> ConsecutivePairs(int num_scans) {
  std::vector<PairIndex> pairs;
  for (int i = 0; i + 1 < num_scans; ++i) pairs.push_back({i, i + 1});
  return pairs;
}

std::vector<int> ConnectedParts(int num_scans, const std::vector<PairIndex>& pairs) {
  std::vector<int> part(static_cast<size_t>(std::max(num_scans, 0)));
  std::iota(part.begin(), part.end(), 0);
  const auto root = [&part](int i) {
    while (part[static_cast<size_t>(i)] != i) i = part[static_cast<size_t>(i)];
    return i;
  };
  for (const PairIndex& p : pairs) {
    const int a = root(p.source), b = root(p.target);
    part[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
  }
  for (int i = 0; i < num_scans; ++i) part[static_cast<size_t>(i)] = root(i);
  return part;
}

void ValidatePairs(int num_scans, const std::vector<PairIndex>& pairs, bool require_connected) {
  std::set<std::pair<int, int>> seen;
  std::vector<int> parent(static_cast<size_t>(std::max(num_scans, 0)));
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const PairIndex& p = pairs[i];
    const std::string where = "pair " + std::to_string(i) + " (" + PairName(p) + ")";
    if (p.source < 0 || p.source >= num_scans || p.target < 0 || p.target >= num_scans) {
      throw InputError(where + ": scan index out of range (the batch has " +
                       std::to_string(num_scans) + " scans)");
    }
    if (p.source == p.target) throw InputError(where + ": a scan cannot be paired with itself");
    const auto key = std::minmax(p.source, p.target);
    if (!seen.insert({key.first, key.second}).second) {
      throw InputError(where + ": the same two scans are already paired");
    }
    parent[FindRoot(parent, p.source)] = FindRoot(parent, p.target);
  }
  if (!require_connected) return;
  for (int i = 1; i < num_scans; ++i) {
    if (FindRoot(parent, i) != FindRoot(parent, 0)) {
      throw InputError("the pairs do not connect scan " + std::to_string(i) +
                       " to scan 0; every scan needs a chain of pairs to the others");
    }
  }
}

PairingPlan PlanFixedPairs(std::vector<PairIndex> chain, std::vector<PairIndex> extras) {
  PairingPlan plan;
  plan.chain = std::move(chain);
  plan.extras = std::move(extras);
  return plan;
}

PairingPlan PlanKeyframes(double overlap_threshold, std::vector<PairIndex> extras) {
  PairingPlan plan;
  plan.keyframes = true;
  plan.overlap_threshold = overlap_threshold;
  plan.extras = std::move(extras);
  return plan;
}

uint64_t PairSeed(uint64_t job_seed, const PairIndex& pair) {
  const uint64_t packed = (static_cast<uint64_t>(static_cast<uint32_t>(pair.source)) << 32) |
                          static_cast<uint32_t>(pair.target);
  return SplitMix64(SplitMix64(job_seed) ^ packed);
}

double DefaultOverlapThreshold(SensorKind sensor) {
  return sensor == SensorKind::kDepthCamera ? 0.6 : 0.7;
}

KeyframePlanner::KeyframePlanner(int num_scans, double overlap_threshold)
    : num_scans_(num_scans), threshold_(overlap_threshold) {
  if (num_scans < 1) throw InputError("keyframes: a batch needs at least one scan");
  if (!(overlap_threshold > 0.0 && overlap_threshold <= 1.0)) {
    throw InputError("keyframes: overlap threshold must be in (0, 1]");
  }
}

std::vector<PairIndex> KeyframePlanner::NextProbes(int max_count) {
  std::vector<PairIndex> probes;
  while (static_cast<int>(probes.size()) < max_count && next_probe_ < num_scans_) {
    const PairIndex probe{next_probe_++, keyframe_};
    if (outcomes_.count(probe) == 0) probes.push_back(probe);
  }
  return probes;
}

void KeyframePlanner::Record(const PairIndex& pair, const ProbeOutcome& outcome) {
  outcomes_[pair] = outcome;
  Advance();
}

void KeyframePlanner::Advance() {
  while (next_ < num_scans_) {
    const PairIndex probe{next_, keyframe_};
    const auto found = outcomes_.find(probe);
    if (found == outcomes_.end()) return;
    const ProbeOutcome& outcome = found->second;
    const bool sees_enough = !outcome.doubtful && outcome.overlap >= threshold_;
    if (sees_enough || next_ == keyframe_ + 1) {
      chain_.push_back(probe);
      ++next_;
      if (outcome.search_reach > kMaxKeyframeReach) {
        keyframe_ = next_ - 1;  // the scan just attached
        next_probe_ = next_;
      }
      continue;
    }
    // Scan next_ sees too little of the keyframe: the scan before it takes
    // over as keyframe and next_ is probed again against that one.
    keyframe_ = next_ - 1;
    next_probe_ = next_;
  }
}

}  // namespace boicp
