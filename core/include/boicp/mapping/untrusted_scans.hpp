#pragma once
// Scans that no trusted registration ties to any other: where they are is
// a guess, so the map names them and, unless asked to place them, leaves
// them out of the fusion.

#include <string>
#include <vector>

#include "boicp/io/scan_source.hpp"
#include "boicp/mapping/pose_graph.hpp"

namespace boicp {

/// What the map does with a scan that has no trusted pair.
enum class UntrustedScans {
  kLeaveOut,  ///< named, placed for the trajectory, but not fused
  kPlace,     ///< named, and fused where its best doubtful pair puts it
};

/// "leave-out" or "place".
std::string UntrustedScansName(UntrustedScans choice);

/// The choice a name gives; throws InputError naming `field` for any other word.
UntrustedScans UntrustedScansFromName(const std::string& name, const std::string& field);

/// The scans, in index order, that no constraint with `used[e]` true and a
/// confidence of at least kTrustedFrom touches. Preconditions: `used` has
/// one flag per constraint; every index is within [0, num_scans).
std::vector<int> ScansWithoutTrustedPair(int num_scans,
                                         const std::vector<PairConstraint>& constraints,
                                         const std::vector<bool>& used);

/// The file name (no folder) of each of `scans`, indices into `all`.
std::vector<std::string> ScanFileNames(const std::vector<ScanSource>& all,
                                       const std::vector<int>& scans);

/// "2 scans have no trusted pair; left out of the map (--untrusted-scans
/// place fuses them): a.pcd, b.pcd", naming each scan as `names` does;
/// empty when `names` is empty.
/// `left_out`: whether they were left out of the fusion.
std::string UntrustedScansLine(const std::vector<std::string>& names, bool left_out);

/// The line above, naming each of `scans` (indices into `all`) by its file name.
std::string UntrustedScansLine(const std::vector<ScanSource>& all, const std::vector<int>& scans,
                               bool left_out);

}  // namespace boicp
