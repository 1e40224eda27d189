// `boicp health`: the standard gRPC health check, for probes such as a
// Docker HEALTHCHECK.

#include <cstdio>

#include "commands.hpp"
#include "health_check.hpp"
#include "remote_options.hpp"

namespace boicp::cli {

CommandRunner AddHealthCommand(CLI::App& app) {
  auto remote = std::make_shared<RemoteFlags>();
  AddRemoteOptions(app, *remote);
  app.footer(
      "Prints the daemon's status (grpc.health.v1 Check) on stdout: SERVING exits 0; "
      "NOT_SERVING (draining) or anything else exits 1, as does an unreachable daemon.");
  return [remote] {
    return RunRemote("health", *remote, [&] {
      const Daemon daemon = ConnectToDaemon(*remote);
      const client::ServingStatus status = client::CheckHealth(daemon.channel, kControlTimeout);
      std::printf("%s\n", client::ServingStatusName(status).c_str());
      return status == client::ServingStatus::kServing ? kOk : kFailure;
    });
  };
}

}  // namespace boicp::cli
