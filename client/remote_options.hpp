#pragma once
// What every remote subcommand (submit, watch, jobs, show, cancel, health,
// export) shares: the daemon flags, the connection, and turning any failure
// into one "boicp <command>: error: ..." line on stderr and an exit code.

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "boicp/rpc/map_builder_client.hpp"

namespace boicp::cli {

/// Deadline of each control call (GetJob, ListJobs, SubmitBatch...), so that
/// an unreachable daemon fails in seconds instead of hanging.
constexpr std::chrono::seconds kControlTimeout{10};

/// Largest message the client accepts: GetResults carries about 0.5 KB per
/// scan, so show works on batches far beyond gRPC's 4 MiB default.
constexpr int kMaxReceiveBytes = 256 << 20;

struct RemoteFlags {
  std::string server = "127.0.0.1:50051";  // HOST:PORT
  std::string token_file;                  // bearer token (the daemon's --auth-token-file)
  std::string tls_ca;                      // PEM roots; empty = plaintext
  std::string tls_cert, tls_key;           // client certificate for a mutual-TLS daemon
  bool insecure = false;                   // allows the token over plaintext
};

/// Adds --server (default: env BOICP_SERVER, then 127.0.0.1:50051),
/// --token-file, --tls-ca, --tls-cert/--tls-key (mutual TLS) and --insecure
/// (the token may go without TLS only with it).
void AddRemoteOptions(CLI::App& app, RemoteFlags& flags);

/// A channel to the daemon and a client on it whose unary calls carry
/// kControlTimeout.
struct Daemon {
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<rpc::MapBuilderClient> client;
};

/// Reads the token (surrounding whitespace ignored, as the daemon does) and
/// the CA file, and opens a channel (lazily: nothing is sent yet). Throws
/// InputError naming the flag when a file is unreadable or the token empty.
Daemon ConnectToDaemon(const RemoteFlags& flags);

/// Thrown when a watched job ends FAILED or CANCELLED (exit code 1).
class JobEndedBadly : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Runs `body` and returns its exit code. Whatever it throws becomes one line
/// "boicp <command>: error: <message>" on stderr and an exit code:
/// InputError, INVALID_ARGUMENT, NOT_FOUND, UNAUTHENTICATED -> 2 (bad input);
/// anything else (unreachable daemon, job failed, server error) -> 1.
int RunRemote(const std::string& command, const RemoteFlags& flags,
              const std::function<int()>& body);

/// A command on one job: the JOB argument (described by `job_help`), the
/// remote options, and a runner that connects and calls `run` under RunRemote.
std::function<int()> AddJobCommand(CLI::App& app, const std::string& command,
                                   const std::string& job_help,
                                   std::function<int(Daemon&, const std::string& job_id)> run);

}  // namespace boicp::cli
