#pragma once
// One pair registration of a job, as a worker runs it.

#include <functional>

#include "boicp/mapping/pose_graph.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "job_spec.hpp"

namespace boicp::server {

struct PairOutcome {
  ::boicp::v1::PairResult result;
  InformationMatrix information;  // for the pose graph, at the refine voxel
};

/// Core's RegisterBatchPair (the pair's own seed, the scans' prior poses)
/// wrapped into the API's PairResult. Throws
/// Cancelled when `stop_requested` fires, InputError when a scan no longer
/// loads, std::runtime_error for engine failures.
PairOutcome RegisterJobPair(const JobSpec& spec, const PairIndex& pair,
                            const std::function<bool()>& stop_requested);

}  // namespace boicp::server
