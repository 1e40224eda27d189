#pragma once
// Names of the files a finished job leaves in its directory, per export format.

#include <optional>
#include <string>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/v1/map_builder.pb.h"

namespace boicp::server {

/// "map.bt", "map.ot", "trajectory.tum", "trajectory.kitti" or "map.ply";
/// nullopt for a format value that is not one of the five.
std::optional<std::string> ExportFileName(int format);

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
