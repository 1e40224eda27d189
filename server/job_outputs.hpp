#pragma once
// Names of the files a finished job leaves in its directory, per export format.

#include <string>
#include <vector>

#include "boicp/mapping/map_assembly.hpp"

namespace boicp::server {

/// "JOB_DIR/trajectory-driveK" for K = 1 .. drives: the stems of each
/// drive's trajectory files in a job of several.
std::vector<std::string> DriveTrajectoryStems(const std::string& job_dir, size_t drives);

/// Every output of a job, under `job_dir`.
MapOutputPaths JobOutputPaths(const std::string& job_dir);

/// Removes the staging files ("*.tmp") that a daemon killed while writing
/// this job's outputs left in `job_dir`. Only one run of a job writes at a
/// time, so every staging file found there is stale.
void RemoveStagingFiles(const std::string& job_dir);

/// Throws StorageError naming the first output file that is not on disk: a
/// job is recorded SUCCEEDED only with every output in place.
void RequireOutputsWritten(const MapOutputPaths& paths);

}  // namespace boicp::server
