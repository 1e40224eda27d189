#include "boicp/mapping/loop_candidates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <stdexcept>

namespace boicp {
namespace {

// Metres driven from scan 0 to each scan along the chain.
std::vector<double> PathLengths(const std::vector<Transform>& poses) {
  std::vector<double> along(poses.size(), 0.0);
  for (size_t k = 1; k < poses.size(); ++k) {
    along[k] = along[k - 1] +
               (poses[k].topRightCorner<3, 1>() - poses[k - 1].topRightCorner<3, 1>()).norm();
  }
  return along;
}

// Every pair within reach, best (smallest distance over reach) first.
std::vector<LoopCandidate> PairsWithinReach(const std::vector<Transform>& poses,
                                            const std::vector<Point>& view_centres,
                                            const LoopCandidateOptions& options) {
  const std::vector<double> along = PathLengths(poses);
  std::vector<LoopCandidate> within;
  const int n = static_cast<int>(poses.size());
  for (int later = options.min_sequence_gap; later < n; ++later) {
    for (int earlier = 0; earlier + options.min_sequence_gap <= later; ++earlier) {
      const auto i = static_cast<size_t>(earlier), j = static_cast<size_t>(later);
      const double reach = options.reach + options.drift_per_metre * (along[j] - along[i]);
      const double distance = (view_centres[i] - view_centres[j]).norm();
      if (distance > reach) continue;
      LoopCandidate c;
      c.pair = {later, earlier};
      c.prior = poses[i].inverse() * poses[j];
      c.distance = distance;
      c.reach = reach;
      c.path = along[j] - along[i];
      within.push_back(c);
    }
  }
  // The drift a loop may take out, discounted as its views lie farther apart.
  const auto value = [](const LoopCandidate& c) {
    return c.path * (1.0 - c.distance / std::max(c.reach, 1e-12));
  };
  std::stable_sort(
      within.begin(), within.end(),
      [&](const LoopCandidate& a, const LoopCandidate& b) { return value(a) > value(b); });
  return within;
}

bool NearKept(const LoopCandidate& c, const std::vector<LoopCandidate>& kept, int spacing) {
  return std::any_of(kept.begin(), kept.end(), [&](const LoopCandidate& k) {
    return std::abs(k.pair.source - c.pair.source) < spacing &&
           std::abs(k.pair.target - c.pair.target) < spacing;
  });
}

}  // namespace

std::string LoopSearchName(LoopSearch search) {
  return search == LoopSearch::kAuto ? "auto" : "off";
}

LoopSearch LoopSearchFromName(const std::string& name, const std::string& field) {
  if (name == "auto" || name.empty()) return LoopSearch::kAuto;
  if (name == "off") return LoopSearch::kOff;
  throw InputError(field + ": '" + name + "' is not auto or off");
}

std::vector<LoopCandidate> LoopCandidatesFromPoses(const std::vector<Transform>& poses,
                                                   const std::vector<Point>& view_centres,
                                                   const LoopCandidateOptions& options) {
  if (view_centres.size() != poses.size()) {
    throw std::invalid_argument("loop candidates: one view centre per pose");
  }
  std::vector<LoopCandidate> kept;
  std::map<int, int> per_scan;
  const auto budget = static_cast<size_t>(
      std::max(1.0, std::floor(options.max_per_drive_scan * static_cast<double>(poses.size()))));
  for (const LoopCandidate& c : PairsWithinReach(poses, view_centres, options)) {
    if (kept.size() >= budget) break;
    if (per_scan[c.pair.source] >= options.max_per_scan) continue;
    if (NearKept(c, kept, options.min_spacing)) continue;
    ++per_scan[c.pair.source];
    kept.push_back(c);
  }
  std::sort(kept.begin(), kept.end(),
            [](const LoopCandidate& a, const LoopCandidate& b) { return a.pair < b.pair; });
  return kept;
}

}  // namespace boicp
