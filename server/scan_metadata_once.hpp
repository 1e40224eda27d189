#pragma once
// A scan's metadata is written once, by its first upload. Scans are named by
// the hash of their bytes alone and batches name only those hashes, so the
// metadata stored with a scan is what every batch naming it reads: another
// client that knows the hash must not be able to change it. A later upload
// of the same bytes is accepted only with metadata a batch would read the
// same way.

#include <string>
#include <vector>

#include "boicp/v1/map_builder.pb.h"

namespace boicp::server {

namespace v1 = ::boicp::v1;

/// What a batch would read differently with `sent` than with `stored`, one
/// "field (stored X, sent Y)" each: the format, a depth image's camera, the
/// sensor origin, the prior pose and the timestamp. Unset fields compare as
/// the values jobs give them (no sensor origin is 0 0 0; no invalid depth
/// values is 0 and 65535); size_bytes and sha256 come from the bytes.
std::vector<std::string> MetadataDifferences(const v1::ScanMetadata& stored,
                                             const v1::ScanMetadata& sent);

/// Throws FAILED_PRECONDITION naming the scan, every difference and what the
/// client can do, unless `sent` reads like `stored`.
void RequireStoredMetadata(const std::string& scan_id, const v1::ScanMetadata& stored,
                           const v1::ScanMetadata& sent);

}  // namespace boicp::server
