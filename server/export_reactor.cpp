#include "export_reactor.hpp"

#include <filesystem>

namespace boicp::server {
namespace {

// Below gRPC's default 4 MiB receive limit, large enough to keep calls few.
constexpr size_t kChunkBytes = 1 << 20;

}  // namespace

ExportReactor::ExportReactor(const std::string& path, const std::string& file_name) {
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  file_.open(path, std::ios::binary);
  if (ec || !file_) {
    Finish(grpc::Status(grpc::StatusCode::INTERNAL, "output " + file_name + " is missing"));
    return;
  }
  chunk_.set_total_size(size);
  chunk_.set_file_name(file_name);
  WriteNext();
}

void ExportReactor::OnWriteDone(bool ok) {
  if (!ok) {
    Finish(grpc::Status(grpc::StatusCode::CANCELLED, "the client went away"));
    return;
  }
  WriteNext();
}

void ExportReactor::WriteNext() {
  std::string& data = *chunk_.mutable_data();
  data.resize(kChunkBytes);
  file_.read(data.data(), static_cast<std::streamsize>(kChunkBytes));
  data.resize(static_cast<size_t>(file_.gcount()));
  if (data.empty() && !first_) {
    Finish(grpc::Status::OK);
    return;
  }
  if (!first_) {
    chunk_.clear_total_size();
    chunk_.clear_file_name();
  }
  first_ = false;
  StartWrite(&chunk_);
}

}  // namespace boicp::server
