#pragma once
// The boicp.v1.MapBuilder service on gRPC's callback API. Handlers only
// validate, read the store and queue work; jobs run on the job manager's
// threads and uploads parse and store their scans on the upload threads,
// never inside a handler, so Server::Shutdown is never blocked by one.

#include <cstdint>

#include "auth.hpp"
#include "boicp/io/decode_budget.hpp"
#include "boicp/util/thread_pool.hpp"
#include "boicp/v1/map_builder.grpc.pb.h"
#include "data_dir.hpp"
#include "job_manager.hpp"
#include "job_store.hpp"
#include "upload_budget.hpp"
#include "upload_watchdog.hpp"
#include "watch_hub.hpp"

namespace boicp::server {

namespace v1 = ::boicp::v1;

struct ServiceDeps {
  JobStore& store;
  DataDir& data_dir;
  JobManager& manager;
  WatchHub& watches;
  const BearerAuth& auth;
  UploadBudget& uploads;
  UploadWatchdog& upload_watchdog;
  // Where uploads check stored copies and parse, store and record their
  // scans; one thread per upload slot (--max-concurrent-uploads).
  ThreadPool& upload_threads;
  uint64_t max_scan_bytes = 0;    // larger uploads are RESOURCE_EXHAUSTED
  uint64_t max_scan_points = 0;   // scans decoding to more points are RESOURCE_EXHAUSTED
  uint64_t min_free_bytes = 0;    // below it uploads and batches are FAILED_PRECONDITION
  uint64_t max_stored_bytes = 0;  // scans and outputs; more is RESOURCE_EXHAUSTED; 0 = no cap
  DecodeBudget* decode_budget = nullptr;  // shared with the job workers; null = no budget
};

/// The freshest view of a job: the newest published snapshot, else the store.
std::optional<v1::Job> FindJob(const ServiceDeps& deps, const std::string& job_id);

class MapBuilderService final : public v1::MapBuilder::CallbackService {
 public:
  explicit MapBuilderService(const ServiceDeps& deps) : deps_(deps) {}

  grpc::ServerReadReactor<v1::UploadScanRequest>* UploadScan(
      grpc::CallbackServerContext* context, v1::UploadScanResponse* response) override;
  grpc::ServerUnaryReactor* FindScans(grpc::CallbackServerContext* context,
                                      const v1::FindScansRequest* request,
                                      v1::FindScansResponse* response) override;
  grpc::ServerUnaryReactor* SubmitBatch(grpc::CallbackServerContext* context,
                                        const v1::SubmitBatchRequest* request,
                                        v1::Job* response) override;
  grpc::ServerUnaryReactor* GetJob(grpc::CallbackServerContext* context,
                                   const v1::GetJobRequest* request, v1::Job* response) override;
  grpc::ServerUnaryReactor* ListJobs(grpc::CallbackServerContext* context,
                                     const v1::ListJobsRequest* request,
                                     v1::ListJobsResponse* response) override;
  grpc::ServerUnaryReactor* DeleteJob(grpc::CallbackServerContext* context,
                                      const v1::DeleteJobRequest* request,
                                      v1::DeleteJobResponse* response) override;
  grpc::ServerUnaryReactor* CancelJob(grpc::CallbackServerContext* context,
                                      const v1::CancelJobRequest* request,
                                      v1::Job* response) override;
  grpc::ServerWriteReactor<v1::JobEvent>* WatchJob(grpc::CallbackServerContext* context,
                                                   const v1::WatchJobRequest* request) override;
  grpc::ServerUnaryReactor* GetResults(grpc::CallbackServerContext* context,
                                       const v1::GetResultsRequest* request,
                                       v1::JobResults* response) override;
  grpc::ServerWriteReactor<v1::ExportChunk>* Export(grpc::CallbackServerContext* context,
                                                    const v1::ExportRequest* request) override;

 private:
  ServiceDeps deps_;
};

}  // namespace boicp::server
