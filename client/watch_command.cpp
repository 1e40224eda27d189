// `boicp watch JOB`: follows a job on the daemon until it ends.

#include "commands.hpp"
#include "remote_options.hpp"
#include "remote_watch.hpp"

namespace boicp::cli {

CommandRunner AddWatchCommand(CLI::App& app) {
  struct Flags {
    RemoteFlags remote;
    std::string job_id;
  };
  auto flags = std::make_shared<Flags>();
  app.add_option("JOB", flags->job_id, "Job id (printed by submit, listed by jobs)")->required();
  AddRemoteOptions(app, flags->remote);
  app.footer(
      "Progress goes to stderr: a redrawn line on a terminal, plain lines otherwise. Exit 0 "
      "when the job succeeded, 1 when it failed or was cancelled. Ctrl-C stops watching, not "
      "the job.");
  return [flags] {
    return RunRemote("watch", flags->remote, [&] {
      Daemon daemon = ConnectToDaemon(flags->remote);
      return FollowJob(daemon, flags->job_id);
    });
  };
}

}  // namespace boicp::cli
