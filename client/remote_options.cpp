#include "remote_options.hpp"

#include <fstream>
#include <sstream>

#include "boicp/util/text.hpp"
#include "boicp/util/types.hpp"
#include "commands.hpp"
#include "run_command.hpp"

namespace boicp::cli {
namespace {

std::string ReadFileOrThrow(const std::string& path, const std::string& flag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(flag + " " + path + ": cannot read");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

std::string DescribeRpcError(const rpc::RpcError& e, const RemoteFlags& flags) {
  switch (e.code()) {
    case grpc::StatusCode::UNAVAILABLE:
      return "cannot reach the daemon at " + flags.server + " (" + e.detail() + ")";
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return "no answer from the daemon at " + flags.server + " within " +
             std::to_string(kControlTimeout.count()) + " s";
    case grpc::StatusCode::UNAUTHENTICATED:
      return flags.token_file.empty()
                 ? "the daemon at " + flags.server +
                       " requires a token: pass --token-file FILE (the file given to boicpd "
                       "--token-file)"
                 : "the daemon at " + flags.server + " rejected the token in " + flags.token_file +
                       " (" + e.detail() + ")";
    case grpc::StatusCode::NOT_FOUND:
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::FAILED_PRECONDITION:
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return e.detail();
    default:
      return e.what();
  }
}

bool IsBadInput(grpc::StatusCode code) {
  return code == grpc::StatusCode::INVALID_ARGUMENT || code == grpc::StatusCode::NOT_FOUND ||
         code == grpc::StatusCode::UNAUTHENTICATED;
}

}  // namespace

void AddRemoteOptions(CLI::App& app, RemoteFlags& flags) {
  app.add_option("--server", flags.server, "boicpd address HOST:PORT")
      ->envname("BOICP_SERVER")
      ->capture_default_str();
  app.add_option("--token-file", flags.token_file,
                 "File holding the bearer token (the daemon's --token-file)");
  app.add_option("--tls-ca", flags.tls_ca,
                 "PEM root certificates of a TLS daemon (else plaintext)");
  app.add_option("--tls-cert", flags.tls_cert,
                 "PEM client certificate, for a daemon run with --tls-client-ca");
  app.add_option("--tls-key", flags.tls_key, "PEM private key of --tls-cert");
  app.add_flag("--insecure", flags.insecure,
               "Send --token-file's token without TLS (readable by anyone on the path)");
}

Daemon ConnectToDaemon(const RemoteFlags& flags) {
  rpc::ConnectOptions options;
  options.address = flags.server;
  options.max_message_bytes = kMaxReceiveBytes;
  if (!flags.token_file.empty()) {
    options.token = Trim(ReadFileOrThrow(flags.token_file, "--token-file"));
    if (options.token.empty()) throw InputError("--token-file " + flags.token_file + ": empty");
  }
  if (!options.token.empty() && flags.tls_ca.empty() && !flags.insecure) {
    throw InputError(
        "--token-file: the token would cross the network in plaintext; give --tls-ca "
        "CA.pem, or --insecure to send it anyway");
  }
  if (!flags.tls_ca.empty()) {
    ReadFileOrThrow(flags.tls_ca, "--tls-ca");  // a clear error before Connect's generic one
    options.tls_ca_file = flags.tls_ca;
  }
  if (flags.tls_cert.empty() != flags.tls_key.empty()) {
    throw InputError("--tls-cert and --tls-key go together");
  }
  if (!flags.tls_cert.empty()) {
    if (flags.tls_ca.empty()) throw InputError("--tls-cert needs --tls-ca");
    ReadFileOrThrow(flags.tls_cert, "--tls-cert");
    ReadFileOrThrow(flags.tls_key, "--tls-key");
    options.tls_cert_file = flags.tls_cert;
    options.tls_key_file = flags.tls_key;
  }
  Daemon daemon;
  daemon.channel = rpc::Connect(options);
  daemon.client = std::make_unique<rpc::MapBuilderClient>(daemon.channel, options.token);
  daemon.client->set_unary_timeout(kControlTimeout);
  return daemon;
}

int RunRemote(const std::string& command, const RemoteFlags& flags,
              const std::function<int()>& body) {
  return RunCommand(command, [&] {
    try {
      return body();
    } catch (const rpc::RpcError& e) {
      return ReportCommandError(command, DescribeRpcError(e, flags),
                                IsBadInput(e.code()) ? kBadInput : kFailure);
    }
  });
}

std::function<int()> AddJobCommand(CLI::App& app, const std::string& command,
                                   const std::string& job_help,
                                   std::function<int(Daemon&, const std::string& job_id)> run) {
  struct Flags {
    RemoteFlags remote;
    std::string job_id;
  };
  auto flags = std::make_shared<Flags>();
  app.add_option("JOB", flags->job_id, job_help)->required();
  AddRemoteOptions(app, flags->remote);
  return [flags, command, run = std::move(run)] {
    return RunRemote(command, flags->remote, [&] {
      Daemon daemon = ConnectToDaemon(flags->remote);
      return run(daemon, flags->job_id);
    });
  };
}

}  // namespace boicp::cli
