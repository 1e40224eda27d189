#pragma once
// Upper bounds on what one batch may ask for, so that no request can make the
// daemon allocate or compute without limit. Each setting's own bounds (the
// search's samples and steps, points per evaluation, search ranges, leaf
// and merged-cloud voxel sizes) are the settings schema's RequestLimits;
// here are those that span fields or are not settings: the map's cells per
// ray, the listed pairs, the label. The scan ids are bounded by
// --max-batch-scans (JobManager::Submit); scan_context must have one entry
// per scan id or none (BuildJobSpec), and the whole request, context
// included, is bounded by --max-message-bytes before it is parsed.

#include <cstddef>

#include "boicp/v1/map_builder.pb.h"

namespace boicp::server {

struct JobLimits {
  double max_cells_per_ray = 20000.0;  // ray length over leaf size
  size_t max_label_bytes = 256;
  int max_listed_pairs = 100000;
};

/// Throws InputError naming the first field over its bound and the bound
/// (the field's path in the request, e.g. "config.random_samples").
void RequireWithinJobLimits(const ::boicp::v1::SubmitBatchRequest& request,
                            const JobLimits& limits = {});

}  // namespace boicp::server
