#pragma once
// One pair registration of a job, as a worker runs it.

#include <functional>

#include "boicp/pose_graph.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "job_spec.hpp"

namespace boicp::server {

struct PairOutcome {
  ::boicp::v1::PairResult result;
  InformationMatrix information;  // for the pose graph, at the refine voxel
};

/// Loads both scans and runs BO-ICP with the pair's own seed (PairSeed of
/// the job seed) and the scans' prior poses when both have one. Throws
/// Cancelled when `stop_requested` fires, InputError when a scan no longer
/// loads, std::runtime_error for engine failures.
PairOutcome RegisterJobPair(const JobSpec& spec, const PairIndex& pair,
                            const std::function<bool()>& stop_requested);

}  // namespace boicp::server
