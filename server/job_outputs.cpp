#include "job_outputs.hpp"

#include <filesystem>

#include "boicp/rpc/proto_convert.hpp"
#include "storage_errors.hpp"

namespace boicp::server {

std::vector<std::string> DriveTrajectoryStems(const std::string& job_dir, size_t drives) {
  std::vector<std::string> stems;
  for (size_t d = 1; d <= drives; ++d) {
    stems.push_back(job_dir + "/" + rpc::DriveTrajectoryStem(static_cast<uint32_t>(d)));
  }
  return stems;
}

MapOutputPaths JobOutputPaths(const std::string& job_dir) {
  MapOutputPaths paths;
  paths.octomap_bt = job_dir + "/map.bt";
  paths.octomap_ot = job_dir + "/map.ot";
  paths.trajectory_tum = job_dir + "/trajectory.tum";
  paths.trajectory_kitti = job_dir + "/trajectory.kitti";
  paths.cloud_ply = job_dir + "/map.ply";
  return paths;
}

void RemoveStagingFiles(const std::string& job_dir) {
  std::error_code error;
  for (std::filesystem::directory_iterator it(job_dir, error), end; !error && it != end;
       it.increment(error)) {
    if (it->path().extension() == ".tmp") {
      std::error_code ignored;
      std::filesystem::remove(it->path(), ignored);
    }
  }
}

void RequireOutputsWritten(const MapOutputPaths& paths) {
  for (const std::string* path : {&paths.octomap_bt, &paths.octomap_ot, &paths.trajectory_tum,
                                  &paths.trajectory_kitti, &paths.cloud_ply}) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(*path, error)) {
      throw StorageError(*path + ": output missing after it was written");
    }
  }
}

}  // namespace boicp::server
