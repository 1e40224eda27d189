#pragma once
// Internal to boicp_core: a binary file read by explicit byte ranges, for
// the bag readers, whose files declare sizes that must not be trusted.

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace boicp::io_detail {

/// Every range is checked against the file's size before anything is
/// allocated for it. Throws InputError naming the file.
class BoundedFile {
 public:
  /// Throws InputError "PATH: cannot open for reading".
  explicit BoundedFile(const std::string& path);

  const std::string& path() const { return path_; }
  uint64_t size() const { return size_; }
  /// True when `count` bytes at `at` lie inside the file.
  bool Has(uint64_t at, uint64_t count) const { return at <= size_ && count <= size_ - at; }

  /// `count` bytes at `at`. Throws InputError "PATH: truncated: ..." when
  /// they run past the end. The caller bounds `count` by its own limits.
  std::vector<uint8_t> ReadAt(uint64_t at, uint64_t count);

 private:
  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
};

/// The unsigned little-endian integer in the `size` (<= 8) bytes at `bytes`.
inline uint64_t LoadLittleEndian(const uint8_t* bytes, int size) {
  uint64_t value = 0;
  for (int i = size - 1; i >= 0; --i) value = (value << 8) | bytes[i];
  return value;
}

}  // namespace boicp::io_detail
