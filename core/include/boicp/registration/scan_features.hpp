#pragma once
// FPFH features of one scan, computed by the first pair that needs them and
// reused by every later pair the scan is in. Both scans of a pair must be
// described at one voxel, so a scan's feature voxel is the search voxel
// coarsened in steps of sqrt(2), and a pair takes the coarser of its two
// scans' steps: the scans of a drive, of similar sizes, are each described
// at one or two voxels whatever their neighbours.

#include <atomic>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>

#include "boicp/registration/fpfh_features.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// One scan's feature cloud.
struct ScanFeatures {
  double voxel = 0.0;     // metres; normals from 3 voxels around a point, FPFH from 5
  Points points;          // the scan's search level downsampled at `voxel`
  FpfhFeatures features;  // one column per point of `points`
};

/// The coarsening step of a scan with `search_points` points at the search
/// voxel: round(log2(search_points / 4000)), at least 0. Matching costs the
/// product of the two clouds' sizes, a surface's points fall with the square
/// of the voxel, and hypotheses need only land in ICP's basin, so a feature
/// cloud holds about 4000 points.
int FeatureStep(size_t search_points);

/// search_voxel * sqrt(2)^step, metres (step >= 0).
double FeatureVoxel(double search_voxel, int step);

/// `search_level` (a scan's points at `search_voxel`) downsampled at
/// FeatureVoxel(search_voxel, step), with its normals (facing `viewpoint`,
/// the sensor in the search level's frame, metres) and FPFH. Does not
/// depend on `threads` (>= 1).
ScanFeatures ComputeScanFeatures(const Points& search_level, double search_voxel, int step,
                                 int threads, const Point& viewpoint = Point::Zero());

/// One scan's ScanFeatures at every step asked of it, each computed once.
/// Safe to call from several threads: a second caller of a step waits for
/// the first, callers of other steps do not.
class ScanFeatureMemo {
 public:
  /// ComputeScanFeatures(search_level, search_voxel, step, threads,
  /// viewpoint) the first time `step` is asked for; every caller must pass
  /// the same scan's search level at the same voxel, seen from the same viewpoint.
  std::shared_ptr<const ScanFeatures> At(const Points& search_level, double search_voxel, int step,
                                         int threads, const Point& viewpoint = Point::Zero());

  /// How many steps have been computed.
  size_t computed() const;

 private:
  struct Entry {
    std::once_flag once;
    std::shared_ptr<const ScanFeatures> features;
  };
  mutable std::mutex mutex_;
  std::map<int, std::unique_ptr<Entry>> entries_;
  std::atomic<size_t> computed_{0};
};

}  // namespace boicp
