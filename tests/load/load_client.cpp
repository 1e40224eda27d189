#include "load_client.hpp"

#include <functional>
#include <random>
#include <thread>

#include "boicp/rpc/health_check.hpp"
#include "boicp/rpc/map_builder_client.hpp"
#include "server_fixture.hpp"

namespace boicp::load {
namespace {

namespace v1 = ::boicp::v1;

constexpr std::chrono::seconds kCallTimeout{30};
constexpr uint32_t kListPageSize = 20;

bool IsFinal(v1::JobState state) {
  return state == v1::JOB_STATE_SUCCEEDED || state == v1::JOB_STATE_FAILED ||
         state == v1::JOB_STATE_CANCELLED;
}

std::shared_ptr<grpc::Channel> Channel(const std::string& address) {
  rpc::ConnectOptions options;
  options.address = address;
  return rpc::Connect(options);
}

// Thrown to end the client after an unexpected error was recorded.
struct ClientStopped {};

class LoadClient {
 public:
  LoadClient(const ClientPlan& plan, const LoadOptions& options, const BatchScans& scans)
      : plan_(plan),
        options_(options),
        scans_(scans),
        channel_(Channel(plan.address)),
        client_(channel_),
        rng_(plan.seed),
        pause_ms_(options.poll_min_ms, options.poll_max_ms) {
    client_.set_unary_timeout(kCallTimeout);
  }

  ClientTotals Run() {
    try {
      for (int batch = 0; Clock::now() < plan_.submit_until; ++batch) {
        RunBatch(MixSeed(plan_.seed, batch), batch);
      }
    } catch (const ClientStopped&) {
      totals_.jobs_unfinished += open_jobs_;
    }
    return std::move(totals_);
  }

 private:
  // Times `call` under `rpc`; an error other than one `expected` accepts is
  // recorded and stops the client.
  template <typename Call>
  auto Timed(const char* rpc, Call&& call,
             const std::function<bool(const rpc::RpcError&)>& expected = {}) -> decltype(call()) {
    const auto start = Clock::now();
    try {
      auto result = call();
      Record(rpc, start);
      return result;
    } catch (const rpc::RpcError& e) {
      if (expected && expected(e)) {
        Record(rpc, start);
        throw;
      }
      totals_.rpc.AddUnexpectedError(rpc, e.what());
    } catch (const std::exception& e) {
      totals_.rpc.AddUnexpectedError(rpc, e.what());
    }
    throw ClientStopped{};
  }

  void Record(const char* rpc, Clock::time_point start) {
    totals_.rpc.AddLatency(rpc,
                           std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }

  void Fail(const std::string& rpc, const std::string& what) {
    totals_.rpc.AddUnexpectedError(rpc, what);
    throw ClientStopped{};
  }

  void Pause() {
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(pause_ms_(rng_)));
  }

  std::vector<std::string> Upload(uint64_t batch_seed) {
    std::vector<std::string> ids;
    for (const std::string& bytes :
         scans_.Make(options_.scans_per_batch, options_.points_per_scan, batch_seed)) {
      v1::ScanMetadata metadata;
      metadata.set_format(v1::SCAN_FORMAT_KITTI_BIN);
      const v1::UploadScanResponse response =
          Timed("UploadScan", [&] { return client_.Upload(bytes, metadata); });
      ++totals_.uploads;
      totals_.uploads_already_present += response.already_present();
      totals_.upload_bytes += bytes.size();
      ids.push_back(response.scan_id());
    }
    return ids;
  }

  // SubmitBatch, retried while the daemon's queue is full.
  v1::Job Submit(const v1::SubmitBatchRequest& request) {
    const auto queue_full = [](const rpc::RpcError& e) {
      return e.code() == grpc::StatusCode::RESOURCE_EXHAUSTED;
    };
    while (true) {
      try {
        return Timed(
            "SubmitBatch", [&] { return client_.Submit(request); }, queue_full);
      } catch (const rpc::RpcError&) {
        ++totals_.submits_rejected;
        if (Clock::now() >= plan_.give_up_at) Fail("SubmitBatch", "queue full until give-up");
        Pause();
      }
    }
  }

  void RunBatch(uint64_t batch_seed, int batch) {
    const std::vector<std::string> ids = Upload(batch_seed);
    v1::FindScansRequest find;
    for (const std::string& id : ids) find.add_scan_ids(id);
    const v1::FindScansResponse found = Timed("FindScans", [&] {
      grpc::ClientContext context;
      client_.Authorize(context);
      context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
      v1::FindScansResponse response;
      const grpc::Status status = client_.stub().FindScans(&context, find, &response);
      if (!status.ok()) throw rpc::RpcError("FindScans", status);
      return response;
    });
    if (found.missing_size() > 0) Fail("FindScans", "uploaded scan missing: " + found.missing(0));

    v1::SubmitBatchRequest request = test::QuickBatch(ids, batch_seed);
    request.set_label("load c" + std::to_string(plan_.index) + " b" + std::to_string(batch));
    const std::string job_id = Submit(request).job_id();
    ++totals_.jobs_submitted;
    ++open_jobs_;
    const v1::Job job = Follow(job_id);
    --open_jobs_;
    Account(job);
  }

  // Polls until the job ends or the give-up time; the control RPCs timed here
  // all run while this job is queued or registering.
  v1::Job Follow(const std::string& job_id) {
    v1::Job job;
    do {
      Pause();
      job = Timed("GetJob", [&] { return client_.GetJob(job_id); });
      const rpc::ServingStatus health =
          Timed("Health", [&] { return rpc::CheckHealth(channel_, kCallTimeout); });
      if (health != rpc::ServingStatus::kServing) {
        Fail("Health", "status " + rpc::ServingStatusName(health));
      }
      Timed("ListJobs", [&] { return client_.ListJobs(kListPageSize); });
    } while (!IsFinal(job.state()) && Clock::now() < plan_.give_up_at);
    return job;
  }

  void Account(const v1::Job& job) {
    if (!IsFinal(job.state())) {
      ++totals_.jobs_unfinished;
      return;
    }
    if (job.state() != v1::JOB_STATE_SUCCEEDED) {
      ++totals_.jobs_failed;
      totals_.job_failures.push_back(job.job_id() + ": " + v1::JobState_Name(job.state()) + " " +
                                     job.error());
      return;
    }
    const v1::JobResults results =
        Timed("GetResults", [&] { return client_.Results(job.job_id()); });
    const int scans = options_.scans_per_batch;
    // Every consecutive pair, and a bridge around any that is doubtful.
    if (results.pairs_size() < scans - 1 || results.trajectory_size() != scans) {
      ++totals_.jobs_failed;
      totals_.job_failures.push_back(job.job_id() + ": succeeded with " +
                                     std::to_string(results.pairs_size()) + " pairs and " +
                                     std::to_string(results.trajectory_size()) + " poses");
      return;
    }
    ++totals_.jobs_succeeded;
    totals_.pairs_completed += job.pairs_done();
  }

  const ClientPlan& plan_;
  const LoadOptions& options_;
  const BatchScans& scans_;
  std::shared_ptr<grpc::Channel> channel_;
  rpc::MapBuilderClient client_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> pause_ms_;
  int open_jobs_ = 0;
  ClientTotals totals_;
};

}  // namespace

void ClientTotals::Merge(const ClientTotals& o) {
  jobs_submitted += o.jobs_submitted;
  jobs_succeeded += o.jobs_succeeded;
  jobs_failed += o.jobs_failed;
  jobs_unfinished += o.jobs_unfinished;
  submits_rejected += o.submits_rejected;
  uploads += o.uploads;
  uploads_already_present += o.uploads_already_present;
  upload_bytes += o.upload_bytes;
  pairs_completed += o.pairs_completed;
  job_failures.insert(job_failures.end(), o.job_failures.begin(), o.job_failures.end());
  rpc.Merge(o.rpc);
}

ClientTotals RunLoadClient(const ClientPlan& plan, const LoadOptions& options,
                           const BatchScans& scans) {
  return LoadClient(plan, options, scans).Run();
}

}  // namespace boicp::load
