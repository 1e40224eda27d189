// `boicp cancel JOB`: asks the daemon to stop a job.

#include <cstdio>

#include "boicp/rpc/proto_convert.hpp"
#include "commands.hpp"
#include "remote_options.hpp"

namespace boicp::cli {

CommandRunner AddCancelCommand(CLI::App& app) {
  app.footer(
      "A queued job is cancelled at once; a running one stops at its next ICP evaluation, "
      "within a few seconds (watch it to see it end). Cancelling a finished job changes "
      "nothing and is not an error.");
  return AddJobCommand(app, "cancel", "Job id", [](Daemon& daemon, const std::string& job_id) {
    const v1::Job job = daemon.client->Cancel(job_id);
    if (job.state() == v1::JOB_STATE_SUCCEEDED || job.state() == v1::JOB_STATE_FAILED) {
      std::fprintf(stderr, "job %s had already %s; nothing to cancel\n", job.job_id().c_str(),
                   rpc::JobStateName(job.state()).c_str());
    } else {
      std::fprintf(
          stderr, "job %s: %s\n", job.job_id().c_str(),
          job.state() == v1::JOB_STATE_CANCELLED ? "cancelled" : "cancel requested, stopping");
    }
    return kOk;
  });
}

}  // namespace boicp::cli
