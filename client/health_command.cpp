// `boicp health`: the standard gRPC health check, for probes such as a
// Docker HEALTHCHECK.

#include <cstdio>

#include "boicp/rpc/health_check.hpp"
#include "commands.hpp"
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
      const rpc::ServingStatus status = rpc::CheckHealth(daemon.channel, kControlTimeout);
      std::printf("%s\n", rpc::ServingStatusName(status).c_str());
      return status == rpc::ServingStatus::kServing ? kOk : kFailure;
    });
  };
}

}  // namespace boicp::cli
