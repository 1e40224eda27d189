#pragma once
// boicpd's command-line settings.

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

namespace boicp::server {

struct DaemonOptions {
  std::string listen = "127.0.0.1:50051";  // HOST:PORT; port 0 picks a free one
  std::string data_dir;
  int workers = 1;               // pair registrations running at once
  int concurrent_jobs = 1;       // jobs running at once
  int registration_threads = 1;  // threads inside one registration
  int max_queued_jobs = 64;
  int max_batch_scans = 100000;
  int max_message_bytes = 4 << 20;         // gRPC receive limit per message
  uint64_t max_scan_bytes = 256ull << 20;  // per uploaded scan
  uint64_t max_scan_points = 5000000;      // per scan, after decoding (about 20 128-beam sweeps)
  uint64_t min_free_mb = 1024;     // MiB kept free in the data directory; new work is refused below
  double retain_days = 0.0;        // finished jobs older than this are deleted; 0 = kept for good
  double scan_grace_hours = 24.0;  // scans no job uses are deleted this long after their last use
  double max_stored_gb = 0.0;      // scans and outputs; uploads over it are refused; 0 = no cap
  uint64_t max_fusion_mb = 0;      // one job's fusion; AddDaemonOptions sets half the memory
  uint64_t max_decode_mb = 512;    // scans decoding at once, uploads and jobs together; 0 = none
  double max_job_seconds = 172800.0;  // a running job fails past it; 0 = no deadline
  int max_concurrent_uploads = 8;
  uint64_t max_upload_bytes_in_flight = 1ull << 30;  // announced by the uploads streaming at once
  int max_concurrent_streams = 100;                  // calls open at once on one connection
  uint64_t grpc_memory_mb = 512;                     // gRPC's own buffers (resource quota)
  int keepalive_s = 60;                              // ping an idle connection this often
  int keepalive_timeout_s = 20;                      // and close it when the ping is not answered
  int idle_connection_s = 600;                       // close a connection with no call this long
  int upload_idle_s = 60;              // cancel an upload that sends nothing this long
  uint64_t min_upload_kib_per_s = 64;  // an upload's average rate past the grace; 0 = none
  int upload_rate_grace_s = 10;        // seconds before the rate is checked
  int max_watch_streams = 256;         // WatchJob streams open at once, all clients together
  std::string auth_token_file;         // --token-file (alias --auth-token-file)
  bool insecure_no_auth = false;       // serve a non-loopback address without a token
  bool insecure = false;               // accept a token over plaintext on a non-loopback address
  std::string tls_cert, tls_key;
  std::string tls_client_ca;      // require client certificates signed by this CA (mutual TLS)
  double shutdown_grace_s = 5.0;  // how long SIGTERM waits for open calls
  std::string log_level = "info";
};

/// Registers the flags on `app`, writing into `options`.
void AddDaemonOptions(CLI::App& app, DaemonOptions& options);

/// True for the loopback hosts of --listen (127.0.0.1, localhost, ::1).
bool IsLoopbackHost(const std::string& host);

/// True when the daemon serves beyond loopback with neither a token nor
/// client certificates (which validation allows only with --insecure-no-auth).
bool IsOpenToAnyone(const DaemonOptions& options);

/// Throws std::invalid_argument naming the first flag out of range, and
/// when a non-loopback --listen is left open: without a token (or client
/// certificates) unless --insecure-no-auth, or with a token over plaintext
/// unless --insecure.
void ValidateDaemonOptions(const DaemonOptions& options);

/// Throws std::invalid_argument when BOICPD_AUTH_TOKEN_FILE is set but empty
/// (`value` is its value, nullptr when unset): read as "no flag", it would
/// turn authentication off without a word.
void RejectEmptyAuthTokenVariable(const char* value);

}  // namespace boicp::server
