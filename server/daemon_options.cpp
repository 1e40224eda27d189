#include "daemon_options.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "boicp/util/parallel_for.hpp"
#include "boicp/util/system_memory.hpp"

namespace boicp::server {

void AddDaemonOptions(CLI::App& app, DaemonOptions& o) {
  // Every flag also reads BOICPD_<FLAG> (a flag on the command line wins), so
  // containers and systemd units configure the daemon without a wrapper script.
  o.workers = AvailableCores();
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
  o.max_fusion_mb = DefaultFusionLimitMb();
  app.add_option("--max-fusion-mb", o.max_fusion_mb,
                 "MiB one job's map fusion may hold (default: half the memory of the machine or "
                 "container); a batch estimated over it is RESOURCE_EXHAUSTED, and a job that "
                 "passes it fails (0 = no limit)")
      ->capture_default_str()
      ->envname("BOICPD_MAX_FUSION_MB");
  app.add_option("--max-decode-mb", o.max_decode_mb,
                 "MiB the scans decoding at once may take, uploads and jobs together (each "
                 "scan's bound from its header); a decode that does not fit waits, and a scan "
                 "whose bound is over it is RESOURCE_EXHAUSTED at upload. The default fits a "
                 "2 GiB pod beside fusion and gRPC, and the largest scan the other limits admit "
                 "(5 M points of 64 bytes, about 440 MiB) still decodes (0 = no limit)")
      ->capture_default_str()
      ->envname("BOICPD_MAX_DECODE_MB");
  app.add_option("--max-job-seconds", o.max_job_seconds,
                 "Seconds a job may run before it fails (0 = no deadline)")
      ->capture_default_str()
      ->envname("BOICPD_MAX_JOB_SECONDS");
  app.add_option("--min-free-mb", o.min_free_mb,
                 "MiB kept free in the data directory: below it boicpd does not start and "
                 "refuses new scans and batches (0 = only a full disk)")
      ->capture_default_str()
      ->envname("BOICPD_MIN_FREE_MB");
  app.add_option("--max-concurrent-uploads", o.max_concurrent_uploads,
                 "Uploads streaming at once (each has a thread to parse and store its scan); "
                 "more is RESOURCE_EXHAUSTED")
      ->capture_default_str()
      ->envname("BOICPD_MAX_CONCURRENT_UPLOADS");
  app.add_option("--max-upload-bytes-in-flight", o.max_upload_bytes_in_flight,
                 "Bytes the uploads streaming at once may announce together")
      ->capture_default_str()
      ->envname("BOICPD_MAX_UPLOAD_BYTES_IN_FLIGHT");
  app.add_option("--max-concurrent-streams", o.max_concurrent_streams,
                 "Calls open at once on one client connection")
      ->capture_default_str()
      ->envname("BOICPD_MAX_CONCURRENT_STREAMS");
  app.add_option("--grpc-memory-mb", o.grpc_memory_mb, "MiB gRPC may use for its buffers")
      ->capture_default_str()
      ->envname("BOICPD_GRPC_MEMORY_MB");
  app.add_option("--keepalive", o.keepalive_s, "Seconds between keepalive pings of a connection")
      ->capture_default_str()
      ->envname("BOICPD_KEEPALIVE");
  app.add_option("--keepalive-timeout", o.keepalive_timeout_s,
                 "Seconds a keepalive ping may go unanswered before the connection closes")
      ->capture_default_str()
      ->envname("BOICPD_KEEPALIVE_TIMEOUT");
  app.add_option("--idle-connection", o.idle_connection_s,
                 "Seconds a connection without calls stays open")
      ->capture_default_str()
      ->envname("BOICPD_IDLE_CONNECTION");
  app.add_option("--upload-idle-timeout", o.upload_idle_s,
                 "Seconds an upload may send nothing before it is cancelled")
      ->capture_default_str()
      ->envname("BOICPD_UPLOAD_IDLE_TIMEOUT");
  app.add_option("--min-upload-kib-per-s", o.min_upload_kib_per_s,
                 "KiB/s an upload must average once --upload-rate-grace has passed (counted "
                 "from its start, less the grace); slower uploads end with DEADLINE_EXCEEDED "
                 "(0 = no minimum)")
      ->capture_default_str()
      ->envname("BOICPD_MIN_UPLOAD_KIB_PER_S");
  app.add_option("--upload-rate-grace", o.upload_rate_grace_s,
                 "Seconds an upload may take before --min-upload-kib-per-s applies")
      ->capture_default_str()
      ->envname("BOICPD_UPLOAD_RATE_GRACE");
  app.add_option("--max-watch-streams", o.max_watch_streams,
                 "WatchJob streams open at once, all clients together; more is "
                 "RESOURCE_EXHAUSTED")
      ->capture_default_str()
      ->envname("BOICPD_MAX_WATCH_STREAMS");
  app.add_option("--retain-days", o.retain_days,
                 "Delete succeeded, failed and cancelled jobs (records and outputs, not scans) "
                 "this many days after they end; 0 keeps them until boicp delete")
      ->capture_default_str()
      ->envname("BOICPD_RETAIN_DAYS");
  app.add_option("--scan-grace-hours", o.scan_grace_hours,
                 "Delete an uploaded scan no job uses this many hours after it was last "
                 "uploaded, found or used")
      ->capture_default_str()
      ->envname("BOICPD_SCAN_GRACE_HOURS");
  app.add_option("--max-stored-gb", o.max_stored_gb,
                 "Refuse uploads (RESOURCE_EXHAUSTED) once scans and outputs take this many GB; "
                 "0 = no cap (the free-space reserve still holds)")
      ->capture_default_str()
      ->envname("BOICPD_MAX_STORED_GB");
  app.add_option("--token-file,--auth-token-file", o.auth_token_file,
                 "Require 'authorization: Bearer <token>' with the token in this file")
      ->envname("BOICPD_AUTH_TOKEN_FILE");
  app.add_flag("--insecure-no-auth", o.insecure_no_auth,
               "Serve a non-loopback --listen without a token: anyone who reaches it can "
               "submit jobs")
      ->envname("BOICPD_INSECURE_NO_AUTH");
  app.add_flag("--insecure", o.insecure,
               "Accept the token over plaintext on a non-loopback --listen (readable by "
               "anyone on the path)")
      ->envname("BOICPD_INSECURE");
  app.add_option("--tls-cert", o.tls_cert, "PEM certificate chain (TLS on with --tls-key)")
      ->envname("BOICPD_TLS_CERT");
  app.add_option("--tls-key", o.tls_key, "PEM private key")->envname("BOICPD_TLS_KEY");
  app.add_option("--tls-client-ca", o.tls_client_ca,
                 "PEM CA: require client certificates it signed (mutual TLS; needs --tls-cert)")
      ->envname("BOICPD_TLS_CLIENT_CA");
  app.add_option("--shutdown-grace", o.shutdown_grace_s,
                 "Seconds SIGTERM waits for open calls before cancelling them")
      ->capture_default_str()
      ->envname("BOICPD_SHUTDOWN_GRACE");
  app.add_option("--log-level", o.log_level, "trace, debug, info, warn or error")
      ->capture_default_str()
      ->envname("BOICPD_LOG_LEVEL");
}

bool IsLoopbackHost(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "[::1]" || host == "::1";
}

bool IsOpenToAnyone(const DaemonOptions& o) {
  const bool authenticated = !o.auth_token_file.empty() || !o.tls_client_ca.empty();
  return !authenticated && !IsLoopbackHost(o.listen.substr(0, o.listen.rfind(':')));
}

namespace {

// Closed by default: what reaches beyond this machine is authenticated, and
// its token does not cross the network in plaintext, unless a flag says so.
void RequireClosedExposure(const DaemonOptions& o) {
  if (IsLoopbackHost(o.listen.substr(0, o.listen.rfind(':')))) return;
  if (IsOpenToAnyone(o) && !o.insecure_no_auth) {
    throw std::invalid_argument(
        "--listen " + o.listen +
        " reaches beyond this machine: give a bearer token with --token-file FILE (and TLS "
        "with --tls-cert and --tls-key), or --insecure-no-auth to serve anyone who can reach it");
  }
  if (!o.auth_token_file.empty() && o.tls_cert.empty() && !o.insecure) {
    throw std::invalid_argument(
        "--token-file: on --listen " + o.listen +
        " the token would cross the network in plaintext; give --tls-cert and --tls-key, or "
        "--insecure to accept it anyway");
  }
}

}  // namespace

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
  require(o.retain_days >= 0.0 && o.retain_days <= 1e5, "--retain-days must be in 0..100000");
  require(o.scan_grace_hours >= 0.0 && o.scan_grace_hours <= 1e6,
          "--scan-grace-hours must be in 0..1000000");
  require(o.max_stored_gb >= 0.0 && o.max_stored_gb <= 1e7, "--max-stored-gb must be in 0..1e7");
  require(o.max_fusion_mb <= (uint64_t{1} << 40), "--max-fusion-mb must be at most 2^40");
  require(o.max_decode_mb <= (uint64_t{1} << 40), "--max-decode-mb must be at most 2^40");
  require(o.max_job_seconds >= 0.0 && o.max_job_seconds <= 1e9,
          "--max-job-seconds must be in 0..1e9");
  require(o.tls_cert.empty() == o.tls_key.empty(), "--tls-cert and --tls-key go together");
  require(o.tls_client_ca.empty() || !o.tls_cert.empty(), "--tls-client-ca needs --tls-cert");
  require(o.max_concurrent_uploads >= 1 && o.max_concurrent_uploads <= 10000,
          "--max-concurrent-uploads must be in 1..10000");
  require(o.max_upload_bytes_in_flight >= 16, "--max-upload-bytes-in-flight must be at least 16");
  require(o.max_concurrent_streams >= 1, "--max-concurrent-streams must be at least 1");
  require(o.grpc_memory_mb >= 16, "--grpc-memory-mb must be at least 16");
  require(o.keepalive_s >= 1 && o.keepalive_timeout_s >= 1 && o.idle_connection_s >= 1,
          "--keepalive, --keepalive-timeout and --idle-connection must be at least 1 s");
  require(o.upload_idle_s >= 1, "--upload-idle-timeout must be at least 1 s");
  require(o.min_upload_kib_per_s <= (uint64_t{1} << 20),
          "--min-upload-kib-per-s must be at most 1048576 (1 GiB/s)");
  require(o.upload_rate_grace_s >= 0 && o.upload_rate_grace_s <= 86400,
          "--upload-rate-grace must be in 0..86400 s");
  require(o.max_watch_streams >= 1 && o.max_watch_streams <= 1000000,
          "--max-watch-streams must be in 1..1000000");
  RequireClosedExposure(o);
  const std::vector<std::string> levels = {"trace", "debug", "info", "warn", "error", "critical"};
  require(std::find(levels.begin(), levels.end(), o.log_level) != levels.end(),
          "--log-level must be trace, debug, info, warn, error or critical");
}

void RejectEmptyAuthTokenVariable(const char* value) {
  if (value != nullptr && *value == '\0') {
    throw std::invalid_argument(
        "BOICPD_AUTH_TOKEN_FILE is set but empty: name the token file, or unset it to run "
        "without authentication");
  }
}

}  // namespace boicp::server
