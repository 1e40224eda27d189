#pragma once
// A batch's scans loaded and prepared once each for the pairs that share
// them: a drive's scan is the target of one pair and the source of the next,
// and both would otherwise load it and prepare it.

#include <list>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/registration/registration_method.hpp"

namespace boicp {

class PreparedScanCache {
 public:
  /// Serves scans[i] as method.Prepare(its points). Keeps the `capacity`
  /// (>= 1) scans asked for most recently: a scan asked for again after it
  /// was dropped is loaded and prepared again, to the same result. `scans`
  /// and `method` must outlive the cache.
  PreparedScanCache(const std::vector<ScanSource>& scans, const RegistrationMethod& method,
                    size_t capacity);

  /// The prepared scans[index]. Thread-safe; callers asking for the same
  /// scan at once wait for one preparation. Throws InputError when the scan
  /// does not load or the index is out of range (and keeps nothing for it).
  std::shared_ptr<const PreparedScan> Get(int index);

 private:
  struct Entry {
    std::mutex building;
    std::shared_ptr<const PreparedScan> prepared;  // null until built
  };

  const std::vector<ScanSource>& scans_;
  const RegistrationMethod& method_;
  size_t capacity_;
  std::mutex mutex_;                                          // guards recent_
  std::list<std::pair<int, std::shared_ptr<Entry>>> recent_;  // most recent first
};

}  // namespace boicp
