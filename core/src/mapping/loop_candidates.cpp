#include "boicp/mapping/loop_candidates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <utility>

#include "boicp/mapping/drives.hpp"

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

// Whether `a` and `b` lie within `spacing` scans of each other at both
// ends, each end in one drive: scans of two drives are no neighbours,
// whatever their indices.
bool Near(const PairIndex& a, const PairIndex& b, int spacing,
          const std::vector<int>& drive_starts) {
  const auto near = [&](int i, int j) {
    return std::abs(i - j) < spacing && DriveOf(drive_starts, i) == DriveOf(drive_starts, j);
  };
  return near(a.source, b.source) && near(a.target, b.target);
}

// `budget_per_scan` times the drive's scans, at least one.
size_t DriveBudget(double budget_per_scan, size_t num_scans) {
  return static_cast<size_t>(
      std::max(1.0, std::floor(budget_per_scan * static_cast<double>(num_scans))));
}

// The candidates `ranked` (best first) taken greedily under the per-scan
// cap, the spacing from those taken and from `near`, and `budget`; sorted
// by pair.
std::vector<LoopCandidate> TakeBest(const std::vector<LoopCandidate>& ranked, size_t budget,
                                    std::vector<PairIndex> near,
                                    const LoopCandidateOptions& options,
                                    const std::vector<int>& drive_starts = {}) {
  std::vector<LoopCandidate> kept;
  std::map<int, int> per_scan;
  for (const LoopCandidate& c : ranked) {
    if (kept.size() >= budget) break;
    if (per_scan[c.pair.source] >= options.max_per_scan) continue;
    if (std::any_of(near.begin(), near.end(), [&](const PairIndex& k) {
          return Near(c.pair, k, options.min_spacing, drive_starts);
        })) {
      continue;
    }
    ++per_scan[c.pair.source];
    kept.push_back(c);
    near.push_back(c.pair);
  }
  std::sort(kept.begin(), kept.end(),
            [](const LoopCandidate& a, const LoopCandidate& b) { return a.pair < b.pair; });
  return kept;
}

// The earlier scans (of an earlier drive, or at least min_sequence_gap
// before `later`; described, of another piece) whose ring keys are nearest
// `later`'s, at most options.place_shortlist of them.
std::vector<int> RingKeyShortlist(const std::vector<PlaceDescriptor>& places,
                                  const std::vector<int>& pieces, int later,
                                  const std::vector<int>& drive_starts,
                                  const LoopCandidateOptions& options) {
  std::vector<std::pair<float, int>> by_key;
  const auto j = static_cast<size_t>(later);
  const int drive = DriveOf(drive_starts, later);
  for (int earlier = 0; earlier < later; ++earlier) {
    const auto i = static_cast<size_t>(earlier);
    if (places[i].empty() || pieces[i] == pieces[j]) continue;
    if (earlier + options.min_sequence_gap > later && DriveOf(drive_starts, earlier) == drive) {
      continue;
    }
    by_key.emplace_back((places[i].ring_key - places[j].ring_key).squaredNorm(), earlier);
  }
  const auto count = std::min(by_key.size(), static_cast<size_t>(options.place_shortlist));
  std::partial_sort(by_key.begin(), by_key.begin() + static_cast<std::ptrdiff_t>(count),
                    by_key.end());
  std::vector<int> shortlist;
  for (size_t k = 0; k < count; ++k) shortlist.push_back(by_key[k].second);
  return shortlist;
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

std::string LoopFoundByName(LoopFoundBy found_by) {
  return found_by == LoopFoundBy::kPlace ? "place" : "poses";
}

std::vector<LoopCandidate> LoopCandidatesFromPoses(const std::vector<Transform>& poses,
                                                   const std::vector<Point>& view_centres,
                                                   const LoopCandidateOptions& options) {
  if (view_centres.size() != poses.size()) {
    throw std::invalid_argument("loop candidates: one view centre per pose");
  }
  return TakeBest(PairsWithinReach(poses, view_centres, options),
                  DriveBudget(options.max_per_drive_scan, poses.size()), {}, options);
}

std::vector<LoopCandidate> LoopCandidatesFromPlaces(const std::vector<PlaceDescriptor>& places,
                                                    const std::vector<Point>& sensor_origins,
                                                    const std::vector<int>& pieces,
                                                    const std::vector<PairIndex>& taken,
                                                    const LoopCandidateOptions& options,
                                                    const std::vector<int>& drive_starts) {
  if (sensor_origins.size() != places.size() || pieces.size() != places.size()) {
    throw std::invalid_argument("loop candidates: one sensor origin and piece per descriptor");
  }
  std::vector<LoopCandidate> best_per_scan;
  const int n = static_cast<int>(places.size());
  for (int later = 1; later < n; ++later) {
    const PlaceDescriptor& place = places[static_cast<size_t>(later)];
    if (place.empty()) continue;
    LoopCandidate best;
    for (const int earlier : RingKeyShortlist(places, pieces, later, drive_starts, options)) {
      const auto i = static_cast<size_t>(earlier), j = static_cast<size_t>(later);
      const PlaceMatch match = MatchPlaces(place, places[i]);
      if (match.distance >= best.place_distance) continue;
      best.pair = {later, earlier};
      best.prior = PlacePrior(match, sensor_origins[j], sensor_origins[i]);
      best.found_by = LoopFoundBy::kPlace;
      best.place_distance = match.distance;
    }
    if (best.found_by == LoopFoundBy::kPlace) best_per_scan.push_back(best);
  }
  // Pairs that join two drives first: without them the drives make no map.
  const auto joins_drives = [&drive_starts](const LoopCandidate& c) {
    return DriveOf(drive_starts, c.pair.source) != DriveOf(drive_starts, c.pair.target);
  };
  std::stable_sort(best_per_scan.begin(), best_per_scan.end(),
                   [&joins_drives](const LoopCandidate& a, const LoopCandidate& b) {
                     if (joins_drives(a) != joins_drives(b)) return joins_drives(a);
                     return a.place_distance < b.place_distance;
                   });
  size_t budget = 0;
  for (size_t d = 0; d <= drive_starts.size(); ++d) {
    const auto [first, end] = DriveScans(drive_starts, n, d);
    budget += DriveBudget(options.max_place_per_drive_scan, static_cast<size_t>(end - first));
  }
  return TakeBest(best_per_scan, budget, taken, options, drive_starts);
}

}  // namespace boicp
