#pragma once
// Whether the data directory can take more work: every directory the daemon
// writes to accepts a new file, and enough space is free. boicpd refuses to
// start, and refuses new scans and batches (FAILED_PRECONDITION), while it
// cannot, so that jobs already accepted keep room for their maps.

#include <cstdint>
#include <optional>
#include <string>

#include "data_dir.hpp"
#include "storage_errors.hpp"

namespace boicp::server {

/// Why `dir` cannot take `incoming_bytes` more now, or nullopt when it can:
/// one of its writable directories refuses a new file (read-only, no
/// permission, gone), no inode is free, or fewer than `reserve_bytes` +
/// `incoming_bytes` bytes are free for unprivileged users. One line that
/// names the directory and the reason (and, in the message but not the
/// reply, the free space).
std::optional<StorageError> FindStorageProblem(const DataDir& dir, uint64_t reserve_bytes,
                                               uint64_t incoming_bytes = 0);

/// Throws FindStorageProblem's StorageError when there is one.
void RequireStorage(const DataDir& dir, uint64_t reserve_bytes, uint64_t incoming_bytes = 0);

/// Throws ServiceError RESOURCE_EXHAUSTED when the stored scans and outputs
/// plus `incoming_bytes` would pass `max_stored_bytes` (0: no cap), naming
/// the flag and what frees room.
void RequireStoredQuota(const DataDir& dir, uint64_t max_stored_bytes, uint64_t incoming_bytes = 0);

}  // namespace boicp::server
