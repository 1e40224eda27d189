#include "bounded_file.hpp"

#include <filesystem>

#include "boicp/util/types.hpp"

namespace boicp::io_detail {

BoundedFile::BoundedFile(const std::string& path) : path_(path), in_(path, std::ios::binary) {
  std::error_code error;
  size_ = std::filesystem::file_size(path, error);
  if (!in_ || error) throw InputError(path + ": cannot open for reading");
}

std::vector<uint8_t> BoundedFile::ReadAt(uint64_t at, uint64_t count) {
  if (!Has(at, count)) {
    throw InputError(path_ + ": truncated: " + std::to_string(count) + " bytes at byte " +
                     std::to_string(at) + " run past the end of the file (" +
                     std::to_string(size_) + " bytes)");
  }
  std::vector<uint8_t> bytes(count);
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(at));
  in_.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(count));
  if (!in_) throw InputError(path_ + ": read error at byte " + std::to_string(at));
  return bytes;
}

}  // namespace boicp::io_detail
