#pragma once
// boicpd assembled: data directory, store, job manager, gRPC server with
// the MapBuilder service, health checking and reflection.

#include <memory>
#include <string>

#include <grpcpp/server.h>

#include "auth.hpp"
#include "boicp/io/decode_budget.hpp"
#include "daemon_options.hpp"
#include "data_dir.hpp"
#include "job_manager.hpp"
#include "job_store.hpp"
#include "service.hpp"
#include "upload_watchdog.hpp"
#include "watch_hub.hpp"

namespace boicp::server {

class Daemon {
 public:
  /// Opens the data directory, resumes unfinished jobs and starts serving.
  /// Throws std::runtime_error when any of that fails (port taken, data
  /// directory locked, unwritable or below --min-free-mb, unreadable TLS files).
  explicit Daemon(const DaemonOptions& options);
  /// Shuts down if Shutdown() was not called.
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  /// "HOST:PORT" with the port actually bound.
  const std::string& address() const { return address_; }

  /// Graceful drain: reports NOT_SERVING, refuses new jobs, stops running
  /// jobs at their next checkpoint (finished pairs are stored; the jobs
  /// resume at the next start), ends watch streams, waits up to the grace
  /// period for open calls, and checkpoints the database. Returns false when
  /// a job was still stopping after the grace period: the caller then exits
  /// without waiting for it (the job resumes at the next start). Idempotent.
  bool Shutdown();

 private:
  DaemonOptions options_;
  BearerAuth auth_;
  std::unique_ptr<DataDir> data_dir_;
  std::unique_ptr<JobStore> store_;
  std::unique_ptr<WatchHub> watches_;
  std::unique_ptr<DecodeBudget> decode_budget_;  // null with --max-decode-mb 0; outlives its users
  std::unique_ptr<JobManager> manager_;
  std::unique_ptr<UploadBudget> uploads_;
  std::unique_ptr<UploadWatchdog> upload_watchdog_;  // outlives the server: its uploads leave it
  std::unique_ptr<ThreadPool> upload_threads_;       // outlives the server: uploads finish on it
  std::unique_ptr<MapBuilderService> service_;
  std::unique_ptr<grpc::Server> server_;
  std::string address_;
  bool stopped_ = false;
  bool jobs_stopped_ = false;
};

}  // namespace boicp::server
