#include "chunk_decompression.hpp"

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <limits>
#include <memory>
#include <string>

#include "boicp/util/types.hpp"

namespace boicp::io_detail {
namespace {

[[noreturn]] void NotItsSize(const char* codec, uint64_t size) {
  throw InputError(std::string("does not decompress to its declared ") + std::to_string(size) +
                   " bytes (" + codec + " data cut short or too long)");
}

void Zstd(const std::vector<uint8_t>& compressed, std::vector<uint8_t>& out, uint64_t size) {
  const size_t got = ZSTD_decompress(out.data(), size, compressed.data(), compressed.size());
  if (ZSTD_isError(got)) throw InputError(std::string("bad zstd data: ") + ZSTD_getErrorName(got));
  if (got != size) NotItsSize("zstd", size);
}

struct Lz4ContextFree {
  void operator()(LZ4F_dctx* context) const { LZ4F_freeDecompressionContext(context); }
};

void Lz4Frame(const std::vector<uint8_t>& compressed, std::vector<uint8_t>& out, uint64_t size) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
    throw InputError("cannot start lz4 decompression");
  }
  const std::unique_ptr<LZ4F_dctx, Lz4ContextFree> context(raw);
  uint64_t in_used = 0;
  uint64_t out_used = 0;
  size_t expecting = 0;  // 0 once a frame is complete
  while (in_used < compressed.size()) {
    size_t out_room = size - out_used;
    size_t in_room = compressed.size() - in_used;
    expecting = LZ4F_decompress(context.get(), out.data() + out_used, &out_room,
                                compressed.data() + in_used, &in_room, nullptr);
    if (LZ4F_isError(expecting)) {
      throw InputError(std::string("bad lz4 data: ") + LZ4F_getErrorName(expecting));
    }
    if (in_room == 0 && out_room == 0) break;  // no progress: the output is full
    in_used += in_room;
    out_used += out_room;
  }
  if (expecting != 0 || in_used != compressed.size() || out_used != size) NotItsSize("lz4", size);
}

void Bzip2(const std::vector<uint8_t>& compressed, std::vector<uint8_t>& out, uint64_t size) {
  constexpr uint64_t kMax = std::numeric_limits<unsigned int>::max();
  if (size > kMax || compressed.size() > kMax) NotItsSize("bz2", size);
  unsigned int produced = static_cast<unsigned int>(size);
  // bzlib's API is not const-correct; it does not write to the source.
  const int result = BZ2_bzBuffToBuffDecompress(
      reinterpret_cast<char*>(out.data()), &produced,
      const_cast<char*>(reinterpret_cast<const char*>(compressed.data())),
      static_cast<unsigned int>(compressed.size()), 0, 0);
  if (result != BZ_OK || produced != size) NotItsSize("bz2", size);
}

}  // namespace

std::vector<uint8_t> DecompressChunk(ChunkCodec codec, const std::vector<uint8_t>& compressed,
                                     uint64_t size) {
  std::vector<uint8_t> out(size + 1);  // never a null destination, even for size 0
  switch (codec) {
    case ChunkCodec::kZstd:
      Zstd(compressed, out, size);
      break;
    case ChunkCodec::kLz4Frame:
      Lz4Frame(compressed, out, size);
      break;
    case ChunkCodec::kBzip2:
      Bzip2(compressed, out, size);
      break;
  }
  out.resize(size);
  return out;
}

}  // namespace boicp::io_detail
