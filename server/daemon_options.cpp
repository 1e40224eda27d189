#include "daemon_options.hpp"

#include <algorithm>
#include <stdexcept>
#include <thread>
#include <vector>

namespace boicp::server {

void AddDaemonOptions(CLI::App& app, DaemonOptions& o) {
  // Every flag also reads BOICPD_<FLAG> (a flag on the command line wins), so
  // containers and systemd units configure the daemon without a wrapper script.
  o.workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  app.add_option("--listen", o.listen, "HOST:PORT to serve on (port 0 picks a free port)")
      ->capture_default_str()
      ->envname("BOICPD_LISTEN");
  app.add_option("--data-dir", o.data_dir, "Directory for the job database, scans and maps")
      ->required()
      ->envname("BOICPD_DATA_DIR");
  app.add_option("--workers", o.workers, "Pair registrations running at once (pool threads)")
      ->capture_default_str()
      ->envname("BOICPD_WORKERS");
  app.add_option("--jobs", o.concurrent_jobs, "Jobs running at once; they share the workers")
      ->capture_default_str()
      ->envname("BOICPD_JOBS");
  app.add_option("--registration-threads", o.registration_threads,
                 "Threads inside one registration (workers x this = registration cores)")
      ->capture_default_str()
      ->envname("BOICPD_REGISTRATION_THREADS");
  app.add_option("--max-queued-jobs", o.max_queued_jobs,
                 "Jobs allowed to wait; more is RESOURCE_EXHAUSTED")
      ->capture_default_str()
      ->envname("BOICPD_MAX_QUEUED_JOBS");
  app.add_option("--max-batch-scans", o.max_batch_scans, "Scans allowed in one batch")
      ->capture_default_str()
      ->envname("BOICPD_MAX_BATCH_SCANS");
  app.add_option("--max-message-bytes", o.max_message_bytes,
                 "Largest gRPC message accepted (upload chunks must fit)")
      ->capture_default_str()
      ->envname("BOICPD_MAX_MESSAGE_BYTES");
  app.add_option("--max-scan-bytes", o.max_scan_bytes, "Largest scan accepted by UploadScan")
      ->capture_default_str()
      ->envname("BOICPD_MAX_SCAN_BYTES");
  app.add_option("--max-scan-points", o.max_scan_points,
                 "Most points one scan may decode to (checked at upload and submission)")
      ->capture_default_str()
      ->envname("BOICPD_MAX_SCAN_POINTS");
  app.add_option("--min-free-mb", o.min_free_mb,
                 "MiB kept free in the data directory: below it boicpd does not start and "
                 "refuses new scans and batches (0 = only a full disk)")
      ->capture_default_str()
      ->envname("BOICPD_MIN_FREE_MB");
  app.add_option("--auth-token-file", o.auth_token_file,
                 "Require 'authorization: Bearer <token>' with the token in this file")
      ->envname("BOICPD_AUTH_TOKEN_FILE");
  app.add_option("--tls-cert", o.tls_cert, "PEM certificate chain (TLS on with --tls-key)")
      ->envname("BOICPD_TLS_CERT");
  app.add_option("--tls-key", o.tls_key, "PEM private key")->envname("BOICPD_TLS_KEY");
  app.add_option("--shutdown-grace", o.shutdown_grace_s,
                 "Seconds SIGTERM waits for open calls before cancelling them")
      ->capture_default_str()
      ->envname("BOICPD_SHUTDOWN_GRACE");
  app.add_option("--log-level", o.log_level, "trace, debug, info, warn or error")
      ->capture_default_str()
      ->envname("BOICPD_LOG_LEVEL");
}

void ValidateDaemonOptions(const DaemonOptions& o) {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument(message);
  };
  require(o.listen.rfind(':') != std::string::npos, "--listen must be HOST:PORT");
  require(o.workers >= 1 && o.workers <= 1024, "--workers must be in 1..1024");
  require(o.concurrent_jobs >= 1 && o.concurrent_jobs <= 1024, "--jobs must be in 1..1024");
  require(o.registration_threads >= 1 && o.registration_threads <= 1024,
          "--registration-threads must be in 1..1024");
  require(o.max_queued_jobs >= 1, "--max-queued-jobs must be at least 1");
  require(o.max_batch_scans >= 2, "--max-batch-scans must be at least 2");
  require(o.max_message_bytes >= 1024, "--max-message-bytes must be at least 1024");
  require(o.max_scan_bytes >= 16, "--max-scan-bytes must be at least 16");
  require(o.max_scan_points >= 1, "--max-scan-points must be at least 1");
  require(o.min_free_mb <= (uint64_t{1} << 40), "--min-free-mb must be at most 2^40");
  require(o.shutdown_grace_s >= 0.0, "--shutdown-grace must be >= 0");
  require(o.tls_cert.empty() == o.tls_key.empty(), "--tls-cert and --tls-key go together");
  const std::vector<std::string> levels = {"trace", "debug", "info", "warn", "error", "critical"};
  require(std::find(levels.begin(), levels.end(), o.log_level) != levels.end(),
          "--log-level must be trace, debug, info, warn, error or critical");
}

}  // namespace boicp::server
