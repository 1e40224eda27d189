#include "service.hpp"

#include <algorithm>

#include "boicp/rpc/proto_convert.hpp"
#include "export_reactor.hpp"
#include "job_outputs.hpp"
#include "service_error.hpp"
#include "upload_reactor.hpp"

namespace boicp::server {
namespace {

constexpr int kDefaultPageSize = 50;
constexpr int kMaxPageSize = 500;
constexpr int kMaxFindScans = 100000;
constexpr uint32_t kMaxResultsPage = 2000;  // pairs, and poses, per GetResults page

// Runs a unary handler: authentication, then `handler`, whose exceptions
// become the matching status.
template <typename Handler>
grpc::ServerUnaryReactor* Unary(const ServiceDeps& deps, grpc::CallbackServerContext* context,
                                const char* rpc, Handler&& handler) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  grpc::Status status = deps.auth.Check(*context);
  if (status.ok()) status = GuardRpc(rpc, std::forward<Handler>(handler));
  reactor->Finish(status);
  return reactor;
}

void RequireJobId(const std::string& job_id) {
  if (job_id.empty()) throw InputError("job_id is required");
}

v1::Job RequireJob(const ServiceDeps& deps, const std::string& job_id) {
  RequireJobId(job_id);
  std::optional<v1::Job> job = FindJob(deps, job_id);
  if (!job) throw ServiceError(grpc::StatusCode::NOT_FOUND, "no job '" + job_id + "'");
  return *job;
}

// Writes one status and ends, for streams refused before they start.
template <typename Message>
class RejectedStream : public grpc::ServerWriteReactor<Message> {
 public:
  explicit RejectedStream(const grpc::Status& status) { this->Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace

std::optional<v1::Job> FindJob(const ServiceDeps& deps, const std::string& job_id) {
  if (std::optional<v1::Job> latest = deps.watches.Latest(job_id)) return latest;
  return deps.store.GetJob(job_id);
}

grpc::ServerReadReactor<v1::UploadScanRequest>* MapBuilderService::UploadScan(
    grpc::CallbackServerContext* context, v1::UploadScanResponse* response) {
  return new UploadReactor(deps_, context, response, deps_.auth.Check(*context));
}

grpc::ServerUnaryReactor* MapBuilderService::FindScans(grpc::CallbackServerContext* context,
                                                       const v1::FindScansRequest* request,
                                                       v1::FindScansResponse* response) {
  return Unary(deps_, context, "FindScans", [&] {
    if (request->scan_ids_size() > kMaxFindScans) {
      throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                         "scan_ids: at most " + std::to_string(kMaxFindScans) + " per call");
    }
    for (const std::string& id : request->scan_ids()) {
      if (!deps_.store.GetScan(id) || !deps_.data_dir.HasScanFile(id)) {
        response->add_missing(id);
      } else {
        deps_.data_dir.TouchScan(
            id);  // found for a batch: spared by the collection of unused scans
      }
    }
    return grpc::Status::OK;
  });
}

grpc::ServerUnaryReactor* MapBuilderService::SubmitBatch(grpc::CallbackServerContext* context,
                                                         const v1::SubmitBatchRequest* request,
                                                         v1::Job* response) {
  return Unary(deps_, context, "SubmitBatch", [&] {
    *response = deps_.manager.Submit(*request);
    return grpc::Status::OK;
  });
}

grpc::ServerUnaryReactor* MapBuilderService::GetJob(grpc::CallbackServerContext* context,
                                                    const v1::GetJobRequest* request,
                                                    v1::Job* response) {
  return Unary(deps_, context, "GetJob", [&] {
    *response = RequireJob(deps_, request->job_id());
    return grpc::Status::OK;
  });
}

grpc::ServerUnaryReactor* MapBuilderService::ListJobs(grpc::CallbackServerContext* context,
                                                      const v1::ListJobsRequest* request,
                                                      v1::ListJobsResponse* response) {
  return Unary(deps_, context, "ListJobs", [&] {
    // Clamped as the unsigned field it is: a size of 2^31 or more is no negative limit.
    const int size = request->page_size() == 0
                         ? kDefaultPageSize
                         : static_cast<int>(std::min<uint32_t>(request->page_size(), kMaxPageSize));
    JobPage page = deps_.store.ListJobs(size, request->page_token());
    for (v1::Job& job : page.jobs) {
      if (std::optional<v1::Job> latest = deps_.watches.Latest(job.job_id())) job = *latest;
      *response->add_jobs() = std::move(job);
    }
    response->set_next_page_token(page.next_page_token);
    return grpc::Status::OK;
  });
}

grpc::ServerUnaryReactor* MapBuilderService::CancelJob(grpc::CallbackServerContext* context,
                                                       const v1::CancelJobRequest* request,
                                                       v1::Job* response) {
  return Unary(deps_, context, "CancelJob", [&] {
    RequireJobId(request->job_id());
    *response = deps_.manager.Cancel(request->job_id());
    return grpc::Status::OK;
  });
}

grpc::ServerUnaryReactor* MapBuilderService::DeleteJob(grpc::CallbackServerContext* context,
                                                       const v1::DeleteJobRequest* request,
                                                       v1::DeleteJobResponse* response) {
  return Unary(deps_, context, "DeleteJob", [&] {
    RequireJobId(request->job_id());
    *response = deps_.manager.Delete(request->job_id());
    return grpc::Status::OK;
  });
}

grpc::ServerWriteReactor<v1::JobEvent>* MapBuilderService::WatchJob(
    grpc::CallbackServerContext* context, const v1::WatchJobRequest* request) {
  grpc::Status status = deps_.auth.Check(*context);
  std::optional<v1::Job> stored;
  if (status.ok()) {
    status = GuardRpc("WatchJob", [&] {
      RequireJobId(request->job_id());
      stored = deps_.store.GetJob(request->job_id());
      return grpc::Status::OK;
    });
  }
  if (!status.ok()) return new RejectedStream<v1::JobEvent>(status);
  return deps_.watches.StartWatch(request->job_id(), stored);
}

grpc::ServerUnaryReactor* MapBuilderService::GetResults(grpc::CallbackServerContext* context,
                                                        const v1::GetResultsRequest* request,
                                                        v1::JobResults* response) {
  return Unary(deps_, context, "GetResults", [&] {
    *response->mutable_job() = RequireJob(deps_, request->job_id());
    // Paged, so that neither the reply nor its copy in memory grows with the
    // job: a page stays near 2 MB (pairs of about 0.4 KB, poses of 0.5 KB),
    // under the default 4 MiB message limit.
    const uint32_t asked = request->page_size();
    const int size =
        static_cast<int>(asked == 0 ? kMaxResultsPage : std::min<uint32_t>(asked, kMaxResultsPage));
    ResultsPage page = deps_.store.GetResultsPage(request->job_id(), size, request->page_token());
    for (v1::PairResult& pair : page.pairs) *response->add_pairs() = std::move(pair);
    for (v1::TrajectoryPose& pose : page.poses) *response->add_trajectory() = std::move(pose);
    response->set_next_page_token(page.next_page_token);
    return grpc::Status::OK;
  });
}

grpc::ServerWriteReactor<v1::ExportChunk>* MapBuilderService::Export(
    grpc::CallbackServerContext* context, const v1::ExportRequest* request) {
  grpc::Status status = deps_.auth.Check(*context);
  std::string path, name;
  if (status.ok()) {
    status = GuardRpc("Export", [&] {
      const v1::Job job = RequireJob(deps_, request->job_id());
      const uint32_t drives = std::max(job.drives(), 1u);
      if (request->drive() > drives) {
        throw InputError("drive: job '" + job.job_id() + "' has " + std::to_string(drives) +
                         (drives == 1 ? " drive" : " drives") + ", not " +
                         std::to_string(request->drive()));
      }
      // The one drive of a job is all of it.
      const uint32_t drive = drives > 1 ? request->drive() : 0;
      const std::optional<std::string> file = rpc::ExportFileName(request->format(), drive);
      if (!file && drive > 0) {
        throw InputError("drive: only the trajectory formats (tum, kitti) are per drive");
      }
      if (!file)
        throw InputError("format: unknown export format " + std::to_string(request->format()));
      if (job.state() != v1::JOB_STATE_SUCCEEDED) {
        throw ServiceError(grpc::StatusCode::FAILED_PRECONDITION,
                           "job '" + job.job_id() + "' is " + rpc::JobStateName(job.state()) +
                               "; its outputs exist once it has succeeded");
      }
      name = *file;
      path = deps_.data_dir.JobDir(job.job_id()) + "/" + name;
      return grpc::Status::OK;
    });
  }
  if (!status.ok()) return new RejectedStream<v1::ExportChunk>(status);
  return new ExportReactor(path, name);
}

}  // namespace boicp::server
