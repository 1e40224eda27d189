#include "boicp/mapping/prepared_scan_cache.hpp"

#include <algorithm>
#include <string>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp {

PreparedScanCache::PreparedScanCache(const std::vector<ScanSource>& scans,
                                     const RegistrationMethod& method, size_t capacity)
    : scans_(scans), method_(method), capacity_(std::max<size_t>(capacity, 1)) {}

std::shared_ptr<const PreparedScan> PreparedScanCache::Get(int index) {
  if (index < 0 || index >= static_cast<int>(scans_.size())) {
    throw InputError("pair index " + std::to_string(index) + " is outside the batch of " +
                     std::to_string(scans_.size()) + " scans");
  }
  std::shared_ptr<Entry> entry;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = std::find_if(recent_.begin(), recent_.end(),
                                    [index](const auto& item) { return item.first == index; });
    if (found != recent_.end()) {
      recent_.splice(recent_.begin(), recent_, found);
    } else {
      recent_.emplace_front(index, std::make_shared<Entry>());
      // A dropped entry lives on in the pairs still holding it.
      if (recent_.size() > capacity_) recent_.pop_back();
    }
    entry = recent_.front().second;
  }
  std::lock_guard<std::mutex> building(entry->building);
  if (!entry->prepared) {
    const ScanSource& scan = scans_[static_cast<size_t>(index)];
    entry->prepared = method_.Prepare(LoadPointCloud(scan.path, scan.load).points);
  }
  return entry->prepared;
}

}  // namespace boicp
