#pragma once
// Shared bodies of the loader and bag harnesses: the fuzz bytes become a scan
// file and go through LoadPointCloud, the one code path the CLI and boicpd
// use, or a bag file read whole through OpenBag.

#include <cstddef>
#include <cstdint>
#include <string>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp::fuzz {

/// Writes `data` to a scratch file of this process and loads it with
/// `options`. InputError is the documented failure and is swallowed; any
/// other exception escapes (libFuzzer reports it). A successful load must
/// hold at least one point and only finite points, else this aborts.
void LoadFuzzBytes(const uint8_t* data, size_t size, const LoadOptions& options);

/// Writes `data` to a scratch file ending in `extension` (".bag", ".db3",
/// ".mcap"), opens it with OpenBag under a 1 MiB message limit, and reads its
/// time range, topics, every topic's messages and every message's bytes.
/// InputError is the documented failure (a message that fails is skipped, as
/// a caller would); a Read longer than the size Messages declared aborts.
void ReadFuzzBag(const uint8_t* data, size_t size, const std::string& extension);

}  // namespace boicp::fuzz
