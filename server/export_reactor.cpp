#include "export_reactor.hpp"

#include <filesystem>
#include <string>
#include <utility>

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

// Each chunk gets a new buffer rather than overwriting the one gRPC has just
// sent from another thread: that hand-over is ordered inside libgrpc, where
// ThreadSanitizer cannot see it, and a reused megabyte is a megabyte of
// suppressed race reports on every chunk.
void ExportReactor::WriteNext() {
  std::string data(kChunkBytes, '\0');
  file_.read(data.data(), static_cast<std::streamsize>(kChunkBytes));
  data.resize(static_cast<size_t>(file_.gcount()));
  const bool empty = data.empty();
  chunk_.set_data(std::move(data));
  if (empty && !first_) {
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
