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
  uint64_t min_free_mb = 1024;  // MiB kept free in the data directory; new work is refused below
  std::string auth_token_file;
  std::string tls_cert, tls_key;
  double shutdown_grace_s = 5.0;  // how long SIGTERM waits for open calls
  std::string log_level = "info";
};

/// Registers the flags on `app`, writing into `options`.
void AddDaemonOptions(CLI::App& app, DaemonOptions& options);

/// Throws std::invalid_argument naming the first flag out of range.
void ValidateDaemonOptions(const DaemonOptions& options);

}  // namespace boicp::server
