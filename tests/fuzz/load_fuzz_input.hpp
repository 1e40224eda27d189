#pragma once
// Shared body of the loader harnesses: the fuzz bytes become a scan file and
// go through LoadPointCloud, the one code path the CLI and boicpd use.

#include <cstddef>
#include <cstdint>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp::fuzz {

/// Writes `data` to a scratch file of this process and loads it with
/// `options`. InputError is the documented failure and is swallowed; any
/// other exception escapes (libFuzzer reports it). A successful load must
/// hold at least one point and only finite points, else this aborts.
void LoadFuzzBytes(const uint8_t* data, size_t size, const LoadOptions& options);

}  // namespace boicp::fuzz
