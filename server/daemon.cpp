#include "daemon.hpp"

#include <chrono>

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/resource_quota.h>
#include <grpcpp/server_builder.h>
#include <spdlog/spdlog.h>

#include "storage_check.hpp"

namespace boicp::server {
namespace {

// Bounds what clients can hold open: gRPC's memory, calls per connection,
// connections that stopped answering or sit idle.
void ApplyTransportLimits(const DaemonOptions& o, grpc::ServerBuilder& builder) {
  grpc::ResourceQuota quota("boicpd");
  quota.Resize(static_cast<size_t>(o.grpc_memory_mb << 20));
  builder.SetResourceQuota(quota);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, o.max_concurrent_streams);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, o.keepalive_s * 1000);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, o.keepalive_timeout_s * 1000);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS, o.idle_connection_s * 1000);
}

}  // namespace

Daemon::Daemon(const DaemonOptions& options) : options_(options) {
  if (!options_.auth_token_file.empty()) {
    auth_ = BearerAuth::FromFile(options_.auth_token_file);
    for (const std::string& warning : BearerAuth::TokenFileWarnings(options_.auth_token_file)) {
      spdlog::warn("{}", warning);
    }
  }
  auto credentials =
      MakeServerCredentials(options_.tls_cert, options_.tls_key, options_.tls_client_ca);

  data_dir_ = std::make_unique<DataDir>(options_.data_dir);
  const uint64_t min_free_bytes = options_.min_free_mb << 20;
  const auto max_stored_bytes = static_cast<uint64_t>(options_.max_stored_gb * 1e9);
  RequireStorage(*data_dir_, min_free_bytes);
  store_ = std::make_unique<JobStore>(data_dir_->DatabasePath());
  watches_ = std::make_unique<WatchHub>(options_.max_watch_streams);
  if (options_.max_decode_mb > 0) {
    decode_budget_ = std::make_unique<DecodeBudget>(options_.max_decode_mb << 20);
  }
  ManagerOptions manager_options;
  manager_options.workers = options_.workers;
  manager_options.concurrent_jobs = options_.concurrent_jobs;
  manager_options.registration_threads = options_.registration_threads;
  manager_options.max_queued_jobs = options_.max_queued_jobs;
  manager_options.max_batch_scans = options_.max_batch_scans;
  manager_options.max_scan_points = options_.max_scan_points;
  manager_options.min_free_bytes = min_free_bytes;
  manager_options.retain_seconds = options_.retain_days * 86400.0;
  manager_options.scan_grace_seconds = options_.scan_grace_hours * 3600.0;
  manager_options.max_stored_bytes = max_stored_bytes;
  manager_options.max_fusion_bytes = static_cast<size_t>(options_.max_fusion_mb << 20);
  manager_options.max_job_seconds = options_.max_job_seconds;
  manager_options.decode_budget = decode_budget_.get();
  manager_ = std::make_unique<JobManager>(*store_, *data_dir_, *watches_, manager_options);
  uploads_ = std::make_unique<UploadBudget>(options_.max_concurrent_uploads,
                                            options_.max_upload_bytes_in_flight);
  UploadWatchdog::Limits pace;
  pace.idle_timeout = std::chrono::seconds(options_.upload_idle_s);
  pace.min_bytes_per_s = options_.min_upload_kib_per_s << 10;
  pace.rate_grace = std::chrono::seconds(options_.upload_rate_grace_s);
  upload_watchdog_ = std::make_unique<UploadWatchdog>(pace);
  upload_threads_ = std::make_unique<ThreadPool>(options_.max_concurrent_uploads);
  service_ = std::make_unique<MapBuilderService>(
      ServiceDeps{*store_, *data_dir_, *manager_, *watches_, auth_, *uploads_, *upload_watchdog_,
                  *upload_threads_, options_.max_scan_bytes, options_.max_scan_points,
                  min_free_bytes, max_stored_bytes, decode_budget_.get()});

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(options_.listen, credentials, &port);
  builder.RegisterService(service_.get());
  builder.SetMaxReceiveMessageSize(options_.max_message_bytes);
  ApplyTransportLimits(options_, builder);
  server_ = builder.BuildAndStart();
  if (!server_ || port == 0) {
    throw std::runtime_error("cannot listen on " + options_.listen +
                             " (address in use or not valid)");
  }
  const std::string host = options_.listen.substr(0, options_.listen.rfind(':'));
  address_ = host + ":" + std::to_string(port);
  manager_->Start();

  if (IsOpenToAnyone(options_)) {
    spdlog::warn(
        "serving {} without a token (--insecure-no-auth): anyone who reaches it can "
        "submit jobs",
        address_);
  }
  spdlog::info("boicpd {} workers x {} registration threads, {} concurrent jobs, data in {}",
               options_.workers, options_.registration_threads, options_.concurrent_jobs,
               data_dir_->root());
  spdlog::info(
      "limits: {} queued jobs, {} scans a batch, {} bytes a message, {} bytes and {} "
      "points a scan; {} MiB kept free; {} MiB of fusion and {} s a job; {} MiB decoding "
      "(0 = no limit)",
      options_.max_queued_jobs, options_.max_batch_scans, options_.max_message_bytes,
      options_.max_scan_bytes, options_.max_scan_points, options_.min_free_mb,
      options_.max_fusion_mb, options_.max_job_seconds, options_.max_decode_mb);
  spdlog::info("auth {}, TLS {}", auth_.enabled() ? "on" : "off",
               options_.tls_cert.empty()        ? "off"
               : options_.tls_client_ca.empty() ? "on"
                                                : "on, client certificates required");
  spdlog::info("listening on {}", address_);
}

Daemon::~Daemon() { Shutdown(); }

bool Daemon::Shutdown() {
  if (stopped_) return jobs_stopped_;
  stopped_ = true;
  spdlog::info("draining: no new jobs; running jobs stop at their next checkpoint");
  if (auto* health = server_->GetHealthCheckService()) health->SetServingStatus(false);
  const auto grace = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(options_.shutdown_grace_s));
  const auto deadline = std::chrono::system_clock::now() + grace;
  jobs_stopped_ = manager_->Drain(grace);
  if (!jobs_stopped_) {
    spdlog::warn(
        "a job is still stopping after {} s (--shutdown-grace); it resumes at the next "
        "start",
        options_.shutdown_grace_s);
  }
  watches_->CloseAll(grpc::Status(grpc::StatusCode::UNAVAILABLE, "boicpd is shutting down"));
  // Uploads waiting for decoding memory end now rather than hold the drain.
  if (decode_budget_) decode_budget_->Close();
  server_->Shutdown(deadline);
  server_->Wait();
  try {
    store_->Checkpoint();
  } catch (const std::exception& e) {
    spdlog::warn("database checkpoint failed: {}", e.what());
  }
  spdlog::info("stopped");
  return jobs_stopped_;
}

}  // namespace boicp::server
