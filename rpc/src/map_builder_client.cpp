#include "boicp/rpc/map_builder_client.hpp"

#include <fstream>
#include <sstream>
#include <tuple>
#include <utility>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/rpc/sha256.hpp"

namespace boicp::rpc {
namespace {

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

void Check(const char* rpc, const grpc::Status& status) {
  if (!status.ok()) throw RpcError(rpc, status);
}

}  // namespace

RpcError::RpcError(const std::string& rpc, const grpc::Status& status)
    : std::runtime_error(rpc + ": " + status.error_message() + " (status " +
                         std::to_string(static_cast<int>(status.error_code())) + ")"),
      code_(status.error_code()),
      detail_(status.error_message()) {}

std::shared_ptr<grpc::Channel> Connect(const ConnectOptions& options) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(options.max_message_bytes);
  arguments.SetMaxSendMessageSize(options.max_message_bytes);
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (!options.tls_ca_file.empty()) {
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = ReadAll(options.tls_ca_file);
    if (!options.tls_cert_file.empty()) {
      ssl.pem_cert_chain = ReadAll(options.tls_cert_file);
      ssl.pem_private_key = ReadAll(options.tls_key_file);
    }
    credentials = grpc::SslCredentials(ssl);
  }
  return grpc::CreateCustomChannel(options.address, credentials, arguments);
}

MapBuilderClient::MapBuilderClient(std::shared_ptr<grpc::Channel> channel, std::string token)
    : stub_(v1::MapBuilder::NewStub(std::move(channel))), token_(std::move(token)) {}

void MapBuilderClient::Authorize(grpc::ClientContext& context) const {
  if (!token_.empty()) context.AddMetadata("authorization", "Bearer " + token_);
}

void MapBuilderClient::PrepareUnary(grpc::ClientContext& context) const {
  Authorize(context);
  if (unary_timeout_.count() > 0) {
    context.set_deadline(std::chrono::system_clock::now() + unary_timeout_);
  }
}

v1::UploadScanResponse MapBuilderClient::Upload(const std::string& bytes, v1::ScanMetadata metadata,
                                                size_t chunk_bytes) {
  const std::string id = ScanId(bytes);
  metadata.set_sha256(id);
  metadata.set_size_bytes(bytes.size());
  // Ask first, so that a scan the daemon holds costs one small call.
  bool present = false;
  {
    grpc::ClientContext context;
    PrepareUnary(context);
    v1::FindScansRequest request;
    request.add_scan_ids(id);
    v1::FindScansResponse response;
    Check("FindScans", stub_->FindScans(&context, request, &response));
    present = response.missing_size() == 0;
  }
  auto send = [&](bool with_bytes) {
    grpc::ClientContext context;
    Authorize(context);
    v1::UploadScanResponse response;
    auto writer = stub_->UploadScan(&context, &response);
    v1::UploadScanRequest message;
    *message.mutable_metadata() = metadata;
    bool open = writer->Write(message);
    for (size_t at = 0; open && with_bytes && at < bytes.size(); at += chunk_bytes) {
      message.set_chunk(bytes.substr(at, chunk_bytes));
      open = writer->Write(message);
    }
    writer->WritesDone();
    const grpc::Status status = writer->Finish();
    return std::make_pair(status, response);
  };
  auto [status, response] = send(!present);
  // The daemon's copy failed its hash check and was set aside: send the bytes.
  if (present && status.error_code() == grpc::StatusCode::DATA_LOSS) {
    std::tie(status, response) = send(true);
  }
  Check("UploadScan", status);
  return response;
}

v1::UploadScanResponse MapBuilderClient::UploadFile(const std::string& path,
                                                    const v1::ScanMetadata& metadata) {
  return Upload(ReadAll(path), metadata);
}

v1::UploadScanResponse MapBuilderClient::UploadScan(const ScanSource& scan,
                                                    const v1::ScanMetadata& metadata) {
  return Upload(ScanUploadBytes(scan), metadata);
}

v1::Job MapBuilderClient::Submit(const v1::SubmitBatchRequest& request) {
  grpc::ClientContext context;
  PrepareUnary(context);
  v1::Job job;
  Check("SubmitBatch", stub_->SubmitBatch(&context, request, &job));
  return job;
}

v1::Job MapBuilderClient::GetJob(const std::string& job_id) {
  grpc::ClientContext context;
  PrepareUnary(context);
  v1::GetJobRequest request;
  request.set_job_id(job_id);
  v1::Job job;
  Check("GetJob", stub_->GetJob(&context, request, &job));
  return job;
}

v1::Job MapBuilderClient::Cancel(const std::string& job_id) {
  grpc::ClientContext context;
  PrepareUnary(context);
  v1::CancelJobRequest request;
  request.set_job_id(job_id);
  v1::Job job;
  Check("CancelJob", stub_->CancelJob(&context, request, &job));
  return job;
}

v1::DeleteJobResponse MapBuilderClient::Delete(const std::string& job_id) {
  grpc::ClientContext context;
  PrepareUnary(context);
  v1::DeleteJobRequest request;
  request.set_job_id(job_id);
  v1::DeleteJobResponse response;
  Check("DeleteJob", stub_->DeleteJob(&context, request, &response));
  return response;
}

v1::ListJobsResponse MapBuilderClient::ListJobs(uint32_t page_size, const std::string& page_token) {
  grpc::ClientContext context;
  PrepareUnary(context);
  v1::ListJobsRequest request;
  request.set_page_size(page_size);
  request.set_page_token(page_token);
  v1::ListJobsResponse response;
  Check("ListJobs", stub_->ListJobs(&context, request, &response));
  return response;
}

v1::JobResults MapBuilderClient::Results(const std::string& job_id, uint32_t page_size) {
  v1::JobResults results;
  v1::GetResultsRequest request;
  request.set_job_id(job_id);
  request.set_page_size(page_size);
  do {
    grpc::ClientContext context;
    PrepareUnary(context);
    v1::JobResults page;
    Check("GetResults", stub_->GetResults(&context, request, &page));
    if (!page.next_page_token().empty() && page.next_page_token() == request.page_token()) {
      throw std::runtime_error("GetResults: the daemon returned the same page token twice");
    }
    // The first page's job: the pages that follow are the results as of then.
    if (!results.has_job()) *results.mutable_job() = std::move(*page.mutable_job());
    for (v1::PairResult& pair : *page.mutable_pairs()) *results.add_pairs() = std::move(pair);
    for (v1::TrajectoryPose& pose : *page.mutable_trajectory()) {
      *results.add_trajectory() = std::move(pose);
    }
    request.set_page_token(page.next_page_token());
  } while (!request.page_token().empty());
  return results;
}

v1::Job MapBuilderClient::Watch(const std::string& job_id,
                                const std::function<void(const v1::JobEvent&)>& on_event) {
  grpc::ClientContext context;
  Authorize(context);
  v1::WatchJobRequest request;
  request.set_job_id(job_id);
  auto reader = stub_->WatchJob(&context, request);
  v1::JobEvent event;
  v1::Job last;
  while (reader->Read(&event)) {
    last = event.job();
    if (on_event) on_event(event);
  }
  Check("WatchJob", reader->Finish());
  return last;
}

uint64_t MapBuilderClient::ExportToFile(const std::string& job_id, v1::ExportFormat format,
                                        const std::string& path, uint32_t drive) {
  grpc::ClientContext context;
  Authorize(context);
  v1::ExportRequest request;
  request.set_job_id(job_id);
  request.set_format(format);
  request.set_drive(drive);
  auto reader = stub_->Export(&context, request);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(path + ": cannot write");
  v1::ExportChunk chunk;
  uint64_t written = 0, expected = 0;
  bool first = true;
  while (reader->Read(&chunk)) {
    if (first) expected = chunk.total_size();
    first = false;
    out.write(chunk.data().data(), static_cast<std::streamsize>(chunk.data().size()));
    written += chunk.data().size();
  }
  Check("Export", reader->Finish());
  if (!out.flush()) throw std::runtime_error(path + ": write failed");
  if (written != expected) {
    throw std::runtime_error(path + ": got " + std::to_string(written) + " of " +
                             std::to_string(expected) + " bytes");
  }
  return written;
}

std::string ScanId(const std::string& bytes) {
  Sha256 hash;
  hash.Update(bytes.data(), bytes.size());
  return hash.HexDigest();
}

std::string ScanUploadBytes(const ScanSource& scan) {
  if (scan.load.format != CloudFormat::kRosMessage) return ReadAll(scan.path);
  return EncodeBinaryPcd(LoadPointCloud(scan.path, scan.load).points);
}

}  // namespace boicp::rpc
