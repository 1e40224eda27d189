// `boicp watch JOB`: follows a job on the daemon until it ends.

#include "commands.hpp"
#include "remote_options.hpp"
#include "remote_watch.hpp"

namespace boicp::cli {

CommandRunner AddWatchCommand(CLI::App& app) {
  app.footer(
      "Progress goes to stderr: a redrawn line on a terminal, plain lines otherwise. Exit 0 "
      "when the job succeeded, 1 when it failed or was cancelled. Ctrl-C stops watching, not "
      "the job.");
  return AddJobCommand(
      app, "watch", "Job id (printed by submit, listed by jobs)",
      [](Daemon& daemon, const std::string& job_id) { return FollowJob(daemon, job_id); });
}

}  // namespace boicp::cli
