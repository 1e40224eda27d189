#pragma once
// Internal to boicp_core: the compressions bag chunks use (MCAP: zstd and
// LZ4 frames; ROS 1: bzip2 and LZ4 frames), each decompressing to exactly
// the size the chunk declares, and never past it.

#include <cstdint>
#include <vector>

namespace boicp::io_detail {

enum class ChunkCodec { kZstd, kLz4Frame, kBzip2 };

/// The `size` bytes `compressed` decompresses to. The caller bounds `size`
/// (BagLimits) before calling. Throws InputError with the problem alone (the
/// caller names the file and the chunk) when the data is corrupt or does not
/// decompress to exactly `size` bytes.
std::vector<uint8_t> DecompressChunk(ChunkCodec codec, const std::vector<uint8_t>& compressed,
                                     uint64_t size);

}  // namespace boicp::io_detail
