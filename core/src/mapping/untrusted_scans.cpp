#include "boicp/mapping/untrusted_scans.hpp"

#include <filesystem>

#include "boicp/util/types.hpp"

namespace boicp {

std::string UntrustedScansName(UntrustedScans choice) {
  return choice == UntrustedScans::kLeaveOut ? "leave-out" : "place";
}

UntrustedScans UntrustedScansFromName(const std::string& name, const std::string& field) {
  if (name == "leave-out" || name.empty()) return UntrustedScans::kLeaveOut;
  if (name == "place") return UntrustedScans::kPlace;
  throw InputError(field + ": '" + name + "' is not leave-out or place");
}

std::vector<int> ScansWithoutTrustedPair(int num_scans,
                                         const std::vector<PairConstraint>& constraints,
                                         const std::vector<bool>& used) {
  std::vector<bool> trusted(static_cast<size_t>(num_scans), false);
  for (size_t e = 0; e < constraints.size(); ++e) {
    if (!used[e] || IsDoubtfulEdge(constraints[e])) continue;
    trusted[static_cast<size_t>(constraints[e].pair.source)] = true;
    trusted[static_cast<size_t>(constraints[e].pair.target)] = true;
  }
  std::vector<int> scans;
  for (int i = 0; i < num_scans; ++i) {
    if (!trusted[static_cast<size_t>(i)]) scans.push_back(i);
  }
  return scans;
}

std::vector<std::string> ScanFileNames(const std::vector<ScanSource>& all,
                                       const std::vector<int>& scans) {
  std::vector<std::string> names;
  for (const int scan : scans) {
    names.push_back(std::filesystem::path(all.at(static_cast<size_t>(scan)).path).filename());
  }
  return names;
}

std::string UntrustedScansLine(const std::vector<std::string>& names, bool left_out) {
  if (names.empty()) return "";
  std::string line = std::to_string(names.size()) +
                     (names.size() == 1 ? " scan has" : " scans have") + " no trusted pair; " +
                     (left_out ? "left out of the map (--untrusted-scans place fuses them): "
                               : "placed by the best doubtful pair: ");
  for (size_t k = 0; k < names.size(); ++k) line += (k > 0 ? ", " : "") + names[k];
  return line;
}

std::string UntrustedScansLine(const std::vector<ScanSource>& all, const std::vector<int>& scans,
                               bool left_out) {
  return UntrustedScansLine(ScanFileNames(all, scans), left_out);
}

}  // namespace boicp
