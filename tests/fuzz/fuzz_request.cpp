// libFuzzer harness for boicpd's request validation. The bytes are a stream
// of length-delimited messages (protobuf's delimited format): a
// SubmitBatchRequest, then one ScanMetadata per scan id (an empty one when
// the stream runs out). Each metadata goes through the UploadScan checks and
// the whole batch through BuildJobSpec. Validation must either accept or
// throw InputError; anything else is a bug.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/util/delimited_message_util.h>

#include "boicp/rpc/proto_convert.hpp"
#include "job_spec.hpp"

namespace {

// The data directory only names scan paths; one per process, removed at exit.
struct ScratchDataDir {
  std::string root =
      (std::filesystem::temp_directory_path() / ("boicp-fuzz-data-" + std::to_string(::getpid())))
          .string();
  boicp::server::DataDir dir{root};
  ~ScratchDataDir() {
    std::error_code ignored;
    std::filesystem::remove_all(root, ignored);
  }
};

const boicp::server::DataDir& FuzzDataDir() {
  static const ScratchDataDir scratch;
  return scratch.dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace v1 = ::boicp::v1;
  using google::protobuf::util::ParseDelimitedFromZeroCopyStream;
  google::protobuf::io::ArrayInputStream stream(data, static_cast<int>(size));
  v1::SubmitBatchRequest request;
  if (!ParseDelimitedFromZeroCopyStream(&request, &stream, nullptr)) return 0;
  std::vector<v1::ScanMetadata> scans(static_cast<size_t>(request.scan_ids_size()));
  for (v1::ScanMetadata& metadata : scans) {
    if (!ParseDelimitedFromZeroCopyStream(&metadata, &stream, nullptr)) metadata.Clear();
    try {
      boicp::rpc::ValidateScanMetadata(metadata);
    } catch (const boicp::InputError&) {
    }
  }
  try {
    boicp::server::BuildJobSpec("fuzz", request, scans, FuzzDataDir(), 1);
  } catch (const boicp::InputError&) {
  }
  return 0;
}
