#include "boicp/mapping/drives.hpp"

#include <algorithm>

#include "boicp/util/types.hpp"

namespace boicp {

int DriveOf(const std::vector<int>& drive_starts, int scan) {
  return static_cast<int>(std::upper_bound(drive_starts.begin(), drive_starts.end(), scan) -
                          drive_starts.begin());
}

std::pair<int, int> DriveScans(const std::vector<int>& drive_starts, int num_scans, size_t drive) {
  return {drive == 0 ? 0 : drive_starts[drive - 1],
          drive < drive_starts.size() ? drive_starts[drive] : num_scans};
}

std::vector<PairIndex> ConsecutivePairsOfDrives(int num_scans,
                                                const std::vector<int>& drive_starts) {
  std::vector<PairIndex> pairs;
  for (int i = 0; i + 1 < num_scans; ++i) {
    if (DriveOf(drive_starts, i) == DriveOf(drive_starts, i + 1)) pairs.push_back({i, i + 1});
  }
  return pairs;
}

void ValidateDriveStarts(int num_scans, const std::vector<int>& drive_starts,
                         const std::vector<std::string>& names) {
  const auto name = [&names](size_t drive) {
    return drive < names.size() ? names[drive] : "drive " + std::to_string(drive + 1);
  };
  for (size_t d = 0; d <= drive_starts.size(); ++d) {
    const auto [first, end] = DriveScans(drive_starts, num_scans, d);
    if (end - first < 2) {
      throw InputError(name(d) + ": a drive needs at least 2 scans, it has " +
                       std::to_string(std::max(end - first, 0)));
    }
  }
}

std::vector<int> DrivesApartFromTheFirst(int num_scans, const std::vector<int>& drive_starts,
                                         const std::vector<PairIndex>& edges) {
  const std::vector<int> part = ConnectedParts(num_scans, edges);
  std::vector<int> apart;
  for (size_t d = 0; d < drive_starts.size(); ++d) {
    if (part[static_cast<size_t>(drive_starts[d])] != 0) apart.push_back(static_cast<int>(d + 1));
  }
  return apart;
}

}  // namespace boicp
