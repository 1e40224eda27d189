#include "boicp/registration/scan_features.hpp"

#include <algorithm>
#include <cmath>

#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/icp/preprocess.hpp"
#include "boicp/icp/surface_normals.hpp"

namespace boicp {

constexpr double kFeaturePoints = 4000.0;

int FeatureStep(size_t search_points) {
  if (static_cast<double>(search_points) <= kFeaturePoints) return 0;
  return static_cast<int>(
      std::lround(std::log2(static_cast<double>(search_points) / kFeaturePoints)));
}

double FeatureVoxel(double search_voxel, int step) {
  return std::ldexp(search_voxel, step / 2) * (step % 2 == 1 ? std::sqrt(2.0) : 1.0);
}

ScanFeatures ComputeScanFeatures(const Points& search_level, double search_voxel, int step,
                                 int threads, const Point& viewpoint) {
  ScanFeatures scan;
  scan.voxel = FeatureVoxel(search_voxel, step);
  const NearestNeighborIndex cloud(VoxelDownsample(search_level, scan.voxel));
  const Points normals = EstimateSurfaceNormals(cloud, 3.0 * scan.voxel, threads);
  scan.features =
      ComputeFpfhFeatures(cloud, normals, 5.0 * scan.voxel, threads, kMaxFpfhNeighbours, viewpoint);
  scan.points = cloud.points();
  return scan;
}

std::shared_ptr<const ScanFeatures> ScanFeatureMemo::At(const Points& search_level,
                                                        double search_voxel, int step, int threads,
                                                        const Point& viewpoint) {
  Entry* entry = nullptr;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::unique_ptr<Entry>& slot = entries_[step];
    if (!slot) slot = std::make_unique<Entry>();
    entry = slot.get();
  }
  // Outside the map's lock, so that other steps are computed meanwhile.
  std::call_once(entry->once, [&] {
    entry->features = std::make_shared<const ScanFeatures>(
        ComputeScanFeatures(search_level, search_voxel, step, threads, viewpoint));
    ++computed_;
  });
  return entry->features;
}

size_t ScanFeatureMemo::computed() const { return computed_.load(); }

}  // namespace boicp
