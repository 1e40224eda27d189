#pragma once
// Internal to boicp_core: reading one serialized ROS message field by field,
// in either serialization, so each message type has a single decoder.
//
// ROS 1: packed little-endian, no alignment; a string is a uint32 length then
// its bytes (no NUL). CDR (ROS 2): a 4-byte encapsulation header (byte 1:
// 0x01 little-endian, 0x00 big-endian), then every primitive aligned to its
// own size counted from the byte after that header; a string's uint32 length
// counts its trailing NUL. Both: a sequence is a uint32 count then elements.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>

#include "boicp/io/bag_reader.hpp"
#include "boicp/util/types.hpp"

namespace boicp::io_detail {

/// Reads fields in order, checking every size against the bytes left first.
/// Every failure throws InputError "WHAT: problem".
class MessageCursor {
 public:
  /// Reads the CDR encapsulation header when `encoding` is kCdr.
  MessageCursor(const uint8_t* data, size_t size, MessageEncoding encoding, std::string what)
      : data_(data), size_(size), encoding_(encoding), what_(std::move(what)) {
    if (encoding_ == MessageEncoding::kCdr) ReadEncapsulation();
  }

  const std::string& what() const { return what_; }
  MessageEncoding encoding() const { return encoding_; }
  size_t remaining() const { return size_ - at_; }

  uint8_t U8(const char* field) { return static_cast<uint8_t>(Primitive(1, field)); }
  uint32_t U32(const char* field) { return static_cast<uint32_t>(Primitive(4, field)); }
  int32_t I32(const char* field) {
    const uint32_t bits = U32(field);
    int32_t value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }
  double F64(const char* field) {
    const uint64_t bits = Primitive(8, field);
    double value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }

  /// A string, without the NUL CDR stores.
  std::string String(const char* field) {
    const uint32_t length = U32(field);
    const uint8_t* bytes = Bytes(length, field);
    size_t used = length;
    if (encoding_ == MessageEncoding::kCdr && used > 0 && bytes[used - 1] == '\0') --used;
    return std::string(reinterpret_cast<const char*>(bytes), used);
  }

  /// A sequence's element count, refused when even `min_element_bytes` per
  /// element could not fit in what is left (so no caller loops or
  /// allocates on a count the message cannot hold).
  uint32_t Count(size_t min_element_bytes, const char* field) {
    const uint32_t count = U32(field);
    if (min_element_bytes > 0 && count > remaining() / min_element_bytes) {
      Fail(std::string(field) + " declares " + std::to_string(count) + " elements but only " +
           std::to_string(remaining()) + " bytes are left");
    }
    return count;
  }

  /// `n` raw bytes (a uint8 sequence's payload), in place.
  const uint8_t* Bytes(size_t n, const char* field) {
    Require(n, field);
    const uint8_t* bytes = data_ + at_;
    at_ += n;
    return bytes;
  }

  /// Skips `count` primitives of `width` bytes (a fixed array).
  void SkipPrimitives(size_t count, size_t width, const char* field) {
    Align(width);
    if (count > remaining() / width) Truncated(field);
    at_ += count * width;
  }

  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(what_ + ": " + problem);
  }

 private:
  void ReadEncapsulation() {
    if (size_ < 4) Fail("truncated CDR encapsulation header");
    if (data_[0] != 0 || data_[1] > 1) {
      Fail("unsupported CDR encapsulation " + std::to_string(data_[0]) + "," +
           std::to_string(data_[1]) + " (plain CDR only)");
    }
    big_endian_ = data_[1] == 0;
    data_ += 4;
    size_ -= 4;
  }

  // CDR aligns each primitive to its own size; ROS 1 packs them.
  void Align(size_t width) {
    if (encoding_ != MessageEncoding::kCdr) return;
    const size_t pad = (width - at_ % width) % width;
    if (pad > remaining()) Truncated("alignment padding");
    at_ += pad;
  }

  void Require(size_t n, const char* field) const {
    if (n > remaining()) Truncated(field);
  }

  [[noreturn]] void Truncated(const char* field) const {
    Fail(std::string("truncated at ") + field + " (byte " + std::to_string(at_) + " of " +
         std::to_string(size_) + ")");
  }

  uint64_t Primitive(size_t width, const char* field) {
    Align(width);
    Require(width, field);
    uint64_t value = 0;
    for (size_t i = 0; i < width; ++i) {
      const size_t shift = big_endian_ ? (width - 1 - i) : i;
      value |= uint64_t{data_[at_ + i]} << (8 * shift);
    }
    at_ += width;
    return value;
  }

  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
  MessageEncoding encoding_;
  bool big_endian_ = false;
  std::string what_;
};

}  // namespace boicp::io_detail
