#include "boicp/io/scan_source.hpp"

namespace boicp {

std::optional<Transform> PairPrior(const ScanSource& source, const ScanSource& target) {
  if (!source.prior_pose || !target.prior_pose) return std::nullopt;
  return Transform(target.prior_pose->inverse() * *source.prior_pose);
}

std::vector<double> ScanTimestamps(const std::vector<ScanSource>& scans) {
  std::vector<double> stamps;
  for (size_t i = 0; i < scans.size(); ++i) {
    stamps.push_back(scans[i].timestamp.value_or(static_cast<double>(i)));
  }
  return stamps;
}

}  // namespace boicp
