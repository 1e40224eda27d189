#pragma once
// A scan's metadata is written once, by its first upload. Scans are named by
// the hash of their bytes alone and batches name only those hashes, so the
// metadata stored with a scan is what batches naming it read: another client
// that knows the hash must not be able to change it.
// - How the bytes decode (format, depth camera) is what a later upload of
//   the same bytes must agree with, else it is refused.
// - The context (sensor origin, prior pose, timestamp) is only the default
//   for batches that send none (SubmitBatchRequest.scan_context): a later
//   upload with another context is a reuse that changes nothing stored.

#include <string>
#include <vector>

#include "boicp/v1/map_builder.pb.h"

namespace boicp::server {

namespace v1 = ::boicp::v1;

/// How `sent` would decode the stored bytes differently from `stored`, one
/// "field (stored X, sent Y)" each: the format and a depth image's camera
/// (fx, fy, cx, cy, depth_scale, invalid_values). Unset fields compare as the
/// values the loader gives them (no invalid depth values is 0 and 65535).
/// The context (sensor origin, prior pose, timestamp) is not compared: the
/// stored one stays, and a batch sends its own. size_bytes and sha256 come
/// from the bytes.
std::vector<std::string> MetadataDifferences(const v1::ScanMetadata& stored,
                                             const v1::ScanMetadata& sent);

/// Throws FAILED_PRECONDITION naming the scan, every difference and what the
/// client can do, unless `sent` decodes the bytes like `stored`.
void RequireStoredMetadata(const std::string& scan_id, const v1::ScanMetadata& stored,
                           const v1::ScanMetadata& sent);

}  // namespace boicp::server
