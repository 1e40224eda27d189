#pragma once
// Upper bounds on what one batch may ask for, so that no request can make the
// daemon allocate or compute without limit: the search's samples and steps
// (the surrogate grows with their square), points per evaluation, search
// ranges, the map's cells per ray and the merged cloud's voxel, the label.

#include <cstdint>

#include "boicp/v1/map_builder.pb.h"

namespace boicp::server {

struct JobLimits {
  int max_random_samples = 1000;
  int max_iterations = 1000;
  uint32_t max_evaluation_points = 1000000;
  double max_range_m = 1000.0;         // search crop and map ray length
  double unlimited_ray_m = 1000.0;     // what a map max_range of 0 (no limit) may reach
  double min_map_resolution_m = 0.01;  // OctoMap leaf
  double max_cells_per_ray = 20000.0;  // ray length over leaf size
  double min_cloud_voxel_m = 0.01;     // merged PLY voxel, when set
  double max_translation_bounds_m = 1000.0;
  size_t max_label_bytes = 256;
  int max_listed_pairs = 100000;
};

/// Throws InputError naming the first field over its bound and the bound.
void RequireWithinJobLimits(const ::boicp::v1::SubmitBatchRequest& request,
                            const JobLimits& limits = {});

}  // namespace boicp::server
