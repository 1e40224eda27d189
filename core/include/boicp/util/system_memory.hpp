#pragma once
// How much memory this process may count on, for defaults that fit the
// machine or the container it runs in.

#include <cstdint>

namespace boicp {

/// The machine's physical memory in bytes, or its cgroup's memory limit
/// (v2 memory.max, v1 memory.limit_in_bytes) when that is lower.
uint64_t UsableMemoryBytes();

/// Half of UsableMemoryBytes() in MiB: the default fusion memory limit,
/// leaving the rest to registration, decoding and the system.
uint64_t DefaultFusionLimitMb();

}  // namespace boicp
