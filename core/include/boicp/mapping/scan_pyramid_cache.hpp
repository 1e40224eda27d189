#pragma once
// A batch's scans loaded, cropped and downsampled once each for the pairs
// that share them: a drive's scan is the target of one pair and the source
// of the next, and both would otherwise load it and build its pyramid.

#include <list>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/registration/refinement.hpp"

namespace boicp {

class ScanPyramidCache {
 public:
  /// Serves scans[i] as BuildScanPyramid(its points, config). Keeps the
  /// `capacity` (>= 1) scans asked for most recently: a scan asked for
  /// again after it was dropped is loaded and built again, to the same
  /// result. `scans` must outlive the cache; config's settings must be final
  /// (config.automatic empty) and valid.
  ScanPyramidCache(const std::vector<ScanSource>& scans, const BoIcpConfig& config,
                   size_t capacity);

  /// The pyramid of scans[index]. Thread-safe; callers asking for the same
  /// scan at once wait for one build. Throws InputError when the scan does
  /// not load or the index is out of range (and keeps nothing for it).
  std::shared_ptr<const ScanPyramid> Get(int index);

 private:
  struct Entry {
    std::mutex building;
    std::shared_ptr<const ScanPyramid> pyramid;  // null until built
  };

  const std::vector<ScanSource>& scans_;
  BoIcpConfig config_;
  size_t capacity_;
  std::mutex mutex_;                                          // guards recent_
  std::list<std::pair<int, std::shared_ptr<Entry>>> recent_;  // most recent first
};

}  // namespace boicp
