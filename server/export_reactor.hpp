#pragma once
// Export: streams one output file of a finished job in 1 MiB chunks, the
// first carrying the file name and total size.

#include <fstream>
#include <string>

#include <grpcpp/support/server_callback.h>

#include "boicp/v1/map_builder.pb.h"

namespace boicp::server {

class ExportReactor : public grpc::ServerWriteReactor<::boicp::v1::ExportChunk> {
 public:
  ExportReactor(const std::string& path, const std::string& file_name);

  void OnWriteDone(bool ok) override;
  void OnDone() override { delete this; }

 private:
  void WriteNext();

  std::ifstream file_;
  ::boicp::v1::ExportChunk chunk_;
  bool first_ = true;
};

}  // namespace boicp::server
