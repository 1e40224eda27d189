#include "boicp/mapping/batch_pairing.hpp"

#include <algorithm>

#include "boicp/mapping/drives.hpp"

namespace boicp {
namespace {

constexpr std::pair<PairingMode, const char*> kModeNames[] = {
    {PairingMode::kConsecutive, "consecutive"},
    {PairingMode::kOverlap, "overlap"},
    {PairingMode::kExplicit, "explicit"}};

void ValidateListedPairs(int num_scans, const std::vector<PairIndex>& pairs, bool require_connected,
                         const std::string& pairs_source) {
  try {
    ValidatePairs(num_scans, pairs, require_connected);
  } catch (const InputError& e) {
    throw InputError(pairs_source + ": " + e.what());
  }
}

}  // namespace

std::string PairingModeName(PairingMode mode) {
  for (const auto& [value, name] : kModeNames) {
    if (value == mode) return name;
  }
  return "unknown";
}

std::optional<PairingMode> PairingModeFromName(const std::string& name) {
  for (const auto& [value, text] : kModeNames) {
    if (name == text) return value;
  }
  return std::nullopt;
}

double BatchOverlapThreshold(const std::vector<ScanSource>& scans,
                             const std::optional<SensorKind>& sensor) {
  if (sensor) return DefaultOverlapThreshold(*sensor);
  const bool depth_images = std::all_of(scans.begin(), scans.end(), [](const ScanSource& scan) {
    return scan.load.format == CloudFormat::kDepthPng;
  });
  return DefaultOverlapThreshold(depth_images ? SensorKind::kDepthCamera : SensorKind::kOther);
}

PairingPlan PlanPairing(const PairingRequest& request, const std::vector<ScanSource>& scans,
                        const std::optional<SensorKind>& sensor, const std::string& pairs_source) {
  const int n = static_cast<int>(scans.size());
  if (!request.drive_starts.empty()) {
    if (request.mode != PairingMode::kConsecutive) {
      throw InputError("several drives: each is chained by consecutive pairing, not " +
                       PairingModeName(request.mode));
    }
    ValidateDriveStarts(n, request.drive_starts);
  }
  switch (request.mode) {
    case PairingMode::kConsecutive: {
      const std::vector<PairIndex> chain = ConsecutivePairsOfDrives(n, request.drive_starts);
      std::vector<PairIndex> all = chain;
      all.insert(all.end(), request.pairs.begin(), request.pairs.end());
      ValidateListedPairs(n, all, /*require_connected=*/request.drive_starts.empty(), pairs_source);
      return PlanFixedPairs(chain, request.pairs);
    }
    case PairingMode::kOverlap: {
      const double threshold = request.overlap_threshold;
      if (threshold != 0.0 && !(threshold > 0.0 && threshold <= 1.0)) {
        throw InputError("pairing.overlap_threshold must be in (0, 1] (0 = default)");
      }
      ValidateListedPairs(n, request.pairs, /*require_connected=*/false, pairs_source);
      return PlanKeyframes(threshold != 0.0 ? threshold : BatchOverlapThreshold(scans, sensor),
                           request.pairs);
    }
    case PairingMode::kExplicit:
      if (request.pairs.empty()) throw InputError(pairs_source + ": explicit pairing needs pairs");
      ValidateListedPairs(n, request.pairs, /*require_connected=*/true, pairs_source);
      return PlanFixedPairs(request.pairs);
  }
  throw InputError("pairing.mode: unknown mode");
}

}  // namespace boicp
