#include "scan_metadata_once.hpp"

#include <algorithm>
#include <charconv>

#include <spdlog/spdlog.h>

#include "boicp/rpc/proto_convert.hpp"
#include "service_error.hpp"

namespace boicp::server {
namespace {

// The shortest text that reads back as the same double, so that two values
// that differ never print alike.
std::string NumberText(double value) {
  if (value == 0.0) value = 0.0;  // -0 reads as 0
  char text[32];
  const std::to_chars_result end = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, end.ptr);
}

std::string ValuesText(const std::vector<uint16_t>& values) {
  std::string text;
  for (uint16_t value : values) text += (text.empty() ? "" : " ") + std::to_string(value);
  return text.empty() ? "none" : text;
}

void AddIfDifferent(std::vector<std::string>& differences, const std::string& field,
                    const std::string& stored, const std::string& sent) {
  if (stored != sent) differences.push_back(field + " (stored " + stored + ", sent " + sent + ")");
}

// The camera as the depth loader applies it; both sides were validated at
// their upload, so both convert.
void AddDepthDifferences(std::vector<std::string>& differences, const v1::ScanMetadata& stored,
                         const v1::ScanMetadata& sent) {
  const DepthOptions a = rpc::LoadOptionsFromMetadata(stored).depth;
  const DepthOptions b = rpc::LoadOptionsFromMetadata(sent).depth;
  AddIfDifferent(differences, "depth.fx", NumberText(a.intrinsics->fx),
                 NumberText(b.intrinsics->fx));
  AddIfDifferent(differences, "depth.fy", NumberText(a.intrinsics->fy),
                 NumberText(b.intrinsics->fy));
  AddIfDifferent(differences, "depth.cx", NumberText(a.intrinsics->cx),
                 NumberText(b.intrinsics->cx));
  AddIfDifferent(differences, "depth.cy", NumberText(a.intrinsics->cy),
                 NumberText(b.intrinsics->cy));
  AddIfDifferent(differences, "depth.depth_scale", NumberText(a.depth_scale),
                 NumberText(b.depth_scale));
  std::vector<uint16_t> invalid_a = a.invalid_values, invalid_b = b.invalid_values;
  std::sort(invalid_a.begin(), invalid_a.end());
  std::sort(invalid_b.begin(), invalid_b.end());
  AddIfDifferent(differences, "depth.invalid_values", ValuesText(invalid_a), ValuesText(invalid_b));
}

}  // namespace

std::vector<std::string> MetadataDifferences(const v1::ScanMetadata& stored,
                                             const v1::ScanMetadata& sent) {
  std::vector<std::string> differences;
  AddIfDifferent(differences, "format", v1::ScanFormat_Name(stored.format()),
                 v1::ScanFormat_Name(sent.format()));
  if (stored.format() == v1::SCAN_FORMAT_DEPTH_PNG && sent.format() == v1::SCAN_FORMAT_DEPTH_PNG) {
    AddDepthDifferences(differences, stored, sent);
  }
  return differences;
}

void RequireStoredMetadata(const std::string& scan_id, const v1::ScanMetadata& stored,
                           const v1::ScanMetadata& sent) {
  const std::vector<std::string> differences = MetadataDifferences(stored, sent);
  if (differences.empty()) return;
  std::string listed;
  for (const std::string& difference : differences) {
    listed += (listed.empty() ? "" : "; ") + difference;
  }
  // The values are numbers and enum names only, so the line is safe to log
  // as is; an operator sees the attempts to rewrite a scan.
  spdlog::warn("scan {}: an upload with other metadata refused: {}", scan_id.substr(0, 12), listed);
  throw ServiceError(
      grpc::StatusCode::FAILED_PRECONDITION,
      "scan " + scan_id + " is stored with other metadata: " + listed +
          ". A scan's metadata is written once, by its first upload, so that no upload changes "
          "what batches naming the scan read: send the stored metadata to use the scan as "
          "stored. Other metadata is accepted once the daemon has let the scan go (no job uses "
          "it, and nobody uploaded or found it for --scan-grace-hours). The sensor origin, prior "
          "pose and timestamp are not part of this: a batch sends its own "
          "(SubmitBatchRequest.scan_context)");
}

}  // namespace boicp::server
