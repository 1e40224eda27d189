// boicpd: the BO-ICP map-building daemon (gRPC API boicp.v1.MapBuilder).

#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>

#include <cstdlib>
#include <cstring>
#include <iostream>

#include <open3d/utility/Logging.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "daemon.hpp"
#include "daemon_options.hpp"

namespace {

sigset_t ShutdownSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  return signals;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"boicpd: BO-ICP map-building daemon (gRPC)"};
  app.set_version_flag("--version", "boicpd " BOICP_VERSION);
  boicp::server::DaemonOptions options;
  boicp::server::AddDaemonOptions(app, options);
  try {
    boicp::server::RejectEmptyAuthTokenVariable(std::getenv("BOICPD_AUTH_TOKEN_FILE"));
    app.parse(argc, argv);
    boicp::server::ValidateDaemonOptions(options);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "boicpd: error: " << e.what() << std::endl;
    return 2;
  }

  spdlog::set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  spdlog::flush_on(spdlog::level::trace);
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Warning);

  // Every thread inherits this mask, so the signals wait for sigwait below
  // instead of interrupting an arbitrary thread.
  const sigset_t signals = ShutdownSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  ::signal(SIGPIPE, SIG_IGN);
  // Scans, maps and the job store are the users' data: the daemon's group may
  // read them, nobody else (a unit's or a container's own umask may be 022).
  ::umask(027);

  try {
    boicp::server::Daemon daemon(options);
    int signal_number = 0;
    sigwait(&signals, &signal_number);
    spdlog::info("received {}", signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
    if (!daemon.Shutdown()) {
      // A job thread is still stopping; everything it finished is stored, so
      // the process ends without waiting for it, as a kill would end it.
      std::_Exit(0);
    }
  } catch (const std::exception& e) {
    spdlog::error("boicpd: {}", e.what());
    return 1;
  }
  return 0;
}
