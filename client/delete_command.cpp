// `boicp delete JOB`: removes a finished job from the daemon.

#include <cstdio>

#include "commands.hpp"
#include "remote_options.hpp"

namespace boicp::cli {

CommandRunner AddDeleteCommand(CLI::App& app) {
  app.footer(
      "Deletes a succeeded, failed or cancelled job: its record, pair results, trajectory and "
      "output files. A queued or running job must be cancelled first. The scans stay.");
  return AddJobCommand(app, "delete", "Job id", [](Daemon& daemon, const std::string& job_id) {
    const v1::DeleteJobResponse deleted = daemon.client->Delete(job_id);
    std::fprintf(stderr, "job %s deleted (%.1f MB of outputs freed)\n", deleted.job_id().c_str(),
                 static_cast<double>(deleted.bytes_freed()) / 1e6);
    return kOk;
  });
}

}  // namespace boicp::cli
