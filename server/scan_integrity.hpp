#pragma once
// Stored scans are named by the SHA-256 of their bytes; a job checks the
// name against the bytes before it uses them, so a scan corrupted on disk
// (bit rot, a stray write, a truncated copy) fails the job loudly instead of
// producing a wrong map.

#include <string>

#include "data_dir.hpp"

namespace boicp::server {

/// Hashes the stored file of `scan_id`. When the bytes no longer match, moves
/// the file aside to ScanPath + ".corrupt" (so FindScans reports the scan
/// missing and a client uploads it again) and throws CorruptScanError naming
/// the scan with "sha256 mismatch". Also throws CorruptScanError when the
/// file is gone, StorageError when it cannot be read.
void VerifyStoredScan(const DataDir& dir, const std::string& scan_id);

}  // namespace boicp::server
