// ROS 2 bags stored as MCAP (https://mcap.dev/spec): after an 8-byte magic,
// records of `opcode u8, length u64 LE, body`; messages lie loose in the data
// section or inside chunks, which may be zstd or lz4 compressed. When the
// summary section holds a chunk index and statistics that account for every
// message, a topic's messages are found by decompressing only the chunks that
// hold that topic; otherwise (no summary, unchunked, or an index that does not
// add up) the whole file is read record by record. Every declared length is
// checked against the bytes present and against BagLimits before anything is
// allocated from it. A chunk's records are checked against its CRC, and the
// summary against the footer's, where the writer stored one (a summary that
// fails its CRC is not used: the whole file is read instead). The data
// section's CRC is not read: it would cost a pass over the whole data
// section, and the chunks' own CRCs already cover their messages.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <zlib.h>

#include "bag_readers.hpp"
#include "boicp/util/types.hpp"
#include "bounded_file.hpp"
#include "chunk_decompression.hpp"

namespace boicp::io_detail {
// Named, so that a unity batch holding another bag reader sees no clash.
namespace mcap_bag {
namespace {

uint32_t Crc32(const std::vector<uint8_t>& bytes) {
  return static_cast<uint32_t>(crc32_z(0, bytes.data(), bytes.size()));
}

std::string Hex(uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", value);
  return text;
}

constexpr uint8_t kMagic[] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint64_t kMagicSize = sizeof(kMagic);
constexpr uint64_t kRecordHeaderSize = 9;    // opcode u8, length u64
constexpr uint64_t kFooterBodySize = 20;     // summary_start, summary_offset_start, summary_crc
constexpr uint64_t kMessageHeaderSize = 22;  // channel u16, sequence u32, log and publish time u64
constexpr uint64_t kChunkFixedSize = 32;     // three times u64, crc u32, compression length u32
constexpr uint64_t kUnchunked = UINT64_MAX;  // BagMessageRef::offset of a message outside chunks

enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
};

const char* RecordName(uint8_t opcode) {
  switch (opcode) {
    case kHeader:
      return "header";
    case kFooter:
      return "footer";
    case kSchema:
      return "schema";
    case kChannel:
      return "channel";
    case kMessage:
      return "message";
    case kChunk:
      return "chunk";
    case kChunkIndex:
      return "chunk index";
    case kStatistics:
      return "statistics";
    default:
      return "record";
  }
}

// Where a record sits, for error messages: a byte of the file, or a byte of
// the decompressed chunk at a byte of the file.
struct Where {
  const std::string* path;
  uint8_t opcode;
  uint64_t at;
  uint64_t chunk_at = kUnchunked;

  [[noreturn]] void Fail(const std::string& problem) const {
    std::string place = std::string(RecordName(opcode)) + " record at byte " + std::to_string(at);
    if (chunk_at != kUnchunked) place += " of the chunk at byte " + std::to_string(chunk_at);
    throw InputError(*path + ": " + place + " " + problem);
  }
};

// Reads a record body's little-endian fields in order, refusing to read past
// its end.
class Cursor {
 public:
  Cursor(const uint8_t* data, uint64_t size, const Where& where)
      : data_(data), size_(size), where_(where) {}

  uint8_t U8() { return static_cast<uint8_t>(LoadLittleEndian(Take(1), 1)); }
  uint16_t U16() { return static_cast<uint16_t>(LoadLittleEndian(Take(2), 2)); }
  uint32_t U32() { return static_cast<uint32_t>(LoadLittleEndian(Take(4), 4)); }
  uint64_t U64() { return LoadLittleEndian(Take(8), 8); }
  std::string String() {
    const uint32_t size = U32();
    const uint8_t* bytes = Take(size);
    return {reinterpret_cast<const char*>(bytes), size};
  }
  // A u32-length-prefixed field (bytes, a map, an array) as a cursor of its own.
  Cursor Sub32() {
    const uint32_t size = U32();
    return Cursor(Take(size), size, where_);
  }
  const uint8_t* Take(uint64_t size) {
    if (size > size_ - used_) {
      where_.Fail("is cut short: a field of " + std::to_string(size) + " bytes at body byte " +
                  std::to_string(used_) + " runs past its end");
    }
    const uint8_t* at = data_ + used_;
    used_ += size;
    return at;
  }
  uint64_t remaining() const { return size_ - used_; }

 private:
  const uint8_t* data_;
  uint64_t size_;
  uint64_t used_ = 0;
  Where where_;
};

struct McapSchema {
  std::string name;  // the message type, "sensor_msgs/msg/PointCloud2"
  std::string encoding;
};

struct McapChannel {
  uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;

  bool operator==(const McapChannel& other) const {
    return schema_id == other.schema_id && topic == other.topic &&
           message_encoding == other.message_encoding;
  }
};

// Schemas and channels by id; chunks and the summary repeat them, identically.
struct Catalog {
  std::map<uint16_t, McapSchema> schemas;
  std::map<uint16_t, McapChannel> channels;
};

// One record inside a decompressed chunk or a summary section.
struct Record {
  uint8_t opcode;
  uint64_t at;  // of its opcode byte, within the buffer
  const uint8_t* body;
  uint64_t size;
};

// Calls `visit` on every record of an in-memory run of records.
template <typename Visit>
void ForEachRecord(const std::vector<uint8_t>& records, const Where& where_in_file, Visit visit) {
  uint64_t at = 0;
  while (at < records.size()) {
    Where where = where_in_file;
    where.opcode = records[at];
    where.at = at;
    if (records.size() - at < kRecordHeaderSize) where.Fail("is cut short: no room for its length");
    const uint64_t size = LoadLittleEndian(&records[at + 1], 8);
    if (size > records.size() - at - kRecordHeaderSize) {
      where.Fail("declares " + std::to_string(size) + " bytes, past the end of what holds it");
    }
    visit(Record{records[at], at, &records[at + kRecordHeaderSize], size}, where);
    at += kRecordHeaderSize + size;
  }
}

// A chunk's index entry from the summary: where the chunk is, which channels
// it holds (empty: unknown, so it is read for every topic).
struct IndexedChunk {
  uint64_t at = 0;
  std::set<uint16_t> channels;
};

// What a usable summary section tells without reading the data section.
struct Summary {
  Catalog catalog;
  std::vector<IndexedChunk> chunks;  // in file order
  std::map<uint16_t, uint64_t> message_counts;
  uint64_t message_count = 0;
  int64_t start_ns = 0;
  int64_t end_ns = 0;
};

// Every message of the file, found by reading it all.
struct FullScan {
  Catalog catalog;
  std::map<uint16_t, std::vector<BagMessageRef>> messages;  // by channel, in file order
};

void SortByLogTime(std::vector<BagMessageRef>* refs) {
  std::stable_sort(refs->begin(), refs->end(), [](const BagMessageRef& a, const BagMessageRef& b) {
    return a.log_time_ns < b.log_time_ns;
  });
}

class McapBag final : public BagReader {
 public:
  McapBag(const std::string& path, const BagLimits& limits)
      : path_(path), limits_(limits), file_(path) {
    RequireMagicAndHeader();
    summary_ = LoadSummary();
  }

  const std::string& path() const override { return path_; }
  BagStorage storage() const override { return BagStorage::kMcap; }
  MessageEncoding encoding() const override { return MessageEncoding::kCdr; }

  std::vector<BagTopic> Topics() override {
    std::map<std::string, BagTopic> by_name;
    const Catalog& catalog = CurrentCatalog();
    for (const auto& [id, channel] : catalog.channels) {
      BagTopic& topic = by_name[channel.topic];
      const std::string type = SchemaName(catalog, id, channel);
      if (!topic.name.empty() && topic.type != type) {
        Fail("topic " + channel.topic + " has two types, " + topic.type + " and " + type);
      }
      topic.name = channel.topic;
      topic.type = type;
      topic.messages += MessageCount(id);
    }
    std::vector<BagTopic> result;
    for (auto& entry : by_name) result.push_back(std::move(entry.second));
    return result;
  }

  std::pair<int64_t, int64_t> TimeRange() override {
    if (summary_) {
      if (summary_->message_count == 0) return {0, 0};
      return {summary_->start_ns, summary_->end_ns};
    }
    bool any = false;
    std::pair<int64_t, int64_t> range{0, 0};
    for (const auto& entry : Scanned().messages) {
      for (const BagMessageRef& ref : entry.second) {
        range.first = any ? std::min(range.first, ref.log_time_ns) : ref.log_time_ns;
        range.second = any ? std::max(range.second, ref.log_time_ns) : ref.log_time_ns;
        any = true;
      }
    }
    return range;
  }

  std::vector<BagMessageRef> Messages(const std::string& topic) override {
    std::set<uint16_t> channels;
    for (const auto& [id, channel] : CurrentCatalog().channels) {
      if (channel.topic != topic) continue;
      RequireCdr(channel);
      channels.insert(id);
    }
    if (channels.empty()) return {};
    if (summary_) {
      std::optional<std::vector<BagMessageRef>> indexed = MessagesThroughIndex(channels);
      if (indexed) return *indexed;
      // The index does not account for every message: read the whole file,
      // whose channels may be more than the summary's.
      summary_.reset();
      return Messages(topic);
    }
    std::vector<BagMessageRef> result;
    for (uint16_t id : channels) {
      const auto found = Scanned().messages.find(id);
      if (found == Scanned().messages.end()) continue;
      result.insert(result.end(), found->second.begin(), found->second.end());
    }
    // Channels of one topic interleave: file order first, so ties keep it.
    std::sort(result.begin(), result.end(), [](const BagMessageRef& a, const BagMessageRef& b) {
      return std::make_pair(a.position, a.offset) < std::make_pair(b.position, b.offset);
    });
    SortByLogTime(&result);
    return result;
  }

  std::vector<uint8_t> Read(const BagMessageRef& message) override {
    // The channels first: without a summary that reads the whole file, which
    // would replace the chunk cached for this message.
    CurrentCatalog();
    if (message.offset == kUnchunked) return ReadLooseMessage(message.position);
    return ReadChunkedMessage(message.position, message.offset);
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(path_ + ": " + problem);
  }

  Where At(uint8_t opcode, uint64_t at) const { return Where{&path_, opcode, at}; }

  void RequireWithinLimit(uint64_t bytes, const Where& where, const char* what) const {
    if (bytes > limits_.max_message_bytes) {
      where.Fail("declares " + std::string(what) + " of " + std::to_string(bytes) +
                 " bytes, over the limit of " + std::to_string(limits_.max_message_bytes));
    }
  }

  // --- the file's frame -----------------------------------------------------

  void RequireMagicAndHeader() {
    if (file_.size() < kMagicSize ||
        std::memcmp(file_.ReadAt(0, kMagicSize).data(), kMagic, kMagicSize) != 0) {
      Fail("not an MCAP file (it does not start with the MCAP magic)");
    }
    const uint8_t opcode = RecordHeaderAt(kMagicSize).first;
    if (opcode != kHeader) {
      Fail("the first record (opcode " + std::to_string(opcode) + ") is not a header");
    }
  }

  // Reads the opcode and body length of the record at `at`, checking the body
  // fits in the file.
  std::pair<uint8_t, uint64_t> RecordHeaderAt(uint64_t at) {
    if (!file_.Has(at, kRecordHeaderSize)) {
      Fail("truncated: the file ends inside the record at byte " + std::to_string(at));
    }
    const std::vector<uint8_t> header = file_.ReadAt(at, kRecordHeaderSize);
    const uint64_t size = LoadLittleEndian(&header[1], 8);
    if (!file_.Has(at + kRecordHeaderSize, size)) {
      At(header[0], at)
          .Fail("declares " + std::to_string(size) + " bytes, past the end of the file (" +
                std::to_string(file_.size()) + " bytes): the file is truncated or corrupt");
    }
    return {header[0], size};
  }

  // A record's whole body, for records that are small by nature (schemas,
  // channels, index entries) but still bounded by the limit.
  std::vector<uint8_t> RecordBody(uint8_t opcode, uint64_t at, uint64_t size) {
    RequireWithinLimit(size, At(opcode, at), "a body");
    return file_.ReadAt(at + kRecordHeaderSize, size);
  }

  // --- records --------------------------------------------------------------

  static void AddSchema(Cursor body, const Where& where, Catalog* catalog) {
    const uint16_t id = body.U16();
    McapSchema schema;
    schema.name = body.String();
    schema.encoding = body.String();
    body.Sub32();  // the message definition, which boicp does not need
    if (id == 0) where.Fail("uses schema id 0, which MCAP reserves for 'no schema'");
    const auto [it, added] = catalog->schemas.emplace(id, schema);
    if (!added && it->second.name != schema.name) {
      where.Fail("redefines schema " + std::to_string(id) + " as " + schema.name + " (was " +
                 it->second.name + ")");
    }
  }

  static void AddChannel(Cursor body, const Where& where, Catalog* catalog) {
    const uint16_t id = body.U16();
    McapChannel channel;
    channel.schema_id = body.U16();
    channel.topic = body.String();
    channel.message_encoding = body.String();
    body.Sub32();  // metadata (QoS profiles), which boicp does not need
    const auto [it, added] = catalog->channels.emplace(id, channel);
    if (!added && !(it->second == channel)) {
      where.Fail("redefines channel " + std::to_string(id) + " (topic " + channel.topic + ", was " +
                 it->second.topic + ")");
    }
  }

  // A message record's reference; `position`/`offset` as BagMessageRef keeps them.
  static std::pair<uint16_t, BagMessageRef> MessageRef(Cursor body, uint64_t size,
                                                       uint64_t position, uint64_t offset) {
    const uint16_t channel = body.U16();
    body.U32();  // sequence
    BagMessageRef ref;
    ref.log_time_ns = static_cast<int64_t>(body.U64());
    body.U64();  // publish time
    ref.position = position;
    ref.offset = offset;
    ref.size = size - kMessageHeaderSize;
    return {channel, ref};
  }

  // --- chunks ---------------------------------------------------------------

  // The decompressed records of the chunk record at `at`; the last one is kept,
  // since reading a topic's messages one by one reads each chunk many times.
  const std::vector<uint8_t>& ChunkRecords(uint64_t at) {
    if (cached_chunk_at_ == at) return cached_chunk_;
    cached_chunk_at_ = kUnchunked;
    cached_chunk_.clear();
    cached_chunk_.shrink_to_fit();
    cached_chunk_ = DecompressedChunk(at);
    cached_chunk_at_ = at;
    return cached_chunk_;
  }

  std::vector<uint8_t> DecompressedChunk(uint64_t at) {
    const auto [opcode, size] = RecordHeaderAt(at);
    const Where where = At(opcode, at);
    if (opcode != kChunk) where.Fail("is where a chunk should be");
    if (size < kChunkFixedSize) where.Fail("is too short for a chunk");
    const uint64_t body_at = at + kRecordHeaderSize;
    std::vector<uint8_t> fixed = file_.ReadAt(body_at, kChunkFixedSize);
    Cursor head(fixed.data(), fixed.size(), where);
    head.U64();  // message start time
    head.U64();  // message end time
    const uint64_t uncompressed_size = head.U64();
    const uint32_t uncompressed_crc = head.U32();
    const uint32_t compression_size = head.U32();
    if (compression_size > size - kChunkFixedSize ||
        size - kChunkFixedSize - compression_size < 8) {
      where.Fail("is cut short: its compression name and records length run past its end");
    }
    std::vector<uint8_t> tail = file_.ReadAt(body_at + kChunkFixedSize, compression_size + 8);
    const std::string compression(tail.begin(), tail.begin() + compression_size);
    const uint64_t records_size = LoadLittleEndian(&tail[compression_size], 8);
    const uint64_t records_at = kChunkFixedSize + compression_size + 8;
    if (records_size > size - records_at) {
      where.Fail("declares " + std::to_string(records_size) + " bytes of records, past its end");
    }
    RequireWithinLimit(records_size, where, "compressed records");
    std::vector<uint8_t> records = file_.ReadAt(body_at + records_at, records_size);
    if (!compression.empty()) {
      if (compression != "zstd" && compression != "lz4") {
        where.Fail("uses compression '" + compression +
                   "'; boicp reads zstd, lz4 and uncompressed chunks");
      }
      RequireWithinLimit(uncompressed_size, where, "an uncompressed size");
      try {
        records = DecompressChunk(compression == "zstd" ? ChunkCodec::kZstd : ChunkCodec::kLz4Frame,
                                  records, uncompressed_size);
      } catch (const InputError& e) {
        where.Fail(e.what());
      }
    }
    // A flipped bit in a point's bytes would otherwise pass as a point
    // elsewhere. 0 means the writer computed no CRC.
    if (uncompressed_crc != 0) {
      const uint32_t computed = Crc32(records);
      if (computed != uncompressed_crc) {
        where.Fail("fails its CRC check (stored " + Hex(uncompressed_crc) + ", computed " +
                   Hex(computed) + "): the bag is corrupt");
      }
    }
    return records;
  }

  // --- the linear scan ------------------------------------------------------

  FullScan& Scanned() {
    if (!scan_) scan_ = ScanWholeFile();
    return *scan_;
  }

  FullScan ScanWholeFile() {
    FullScan scan;
    uint64_t at = kMagicSize;
    while (true) {
      if (at == file_.size()) {
        Fail("truncated: the file ends at byte " + std::to_string(at) +
             " without a footer (a recording cut off? `mcap recover` can repair it)");
      }
      const auto [opcode, size] = RecordHeaderAt(at);
      if (opcode == kFooter) break;
      ScanRecord(opcode, at, size, &scan);
      at += kRecordHeaderSize + size;
    }
    RequireEndMagic(at);
    RequireKnownChannels(scan);
    return scan;
  }

  void ScanRecord(uint8_t opcode, uint64_t at, uint64_t size, FullScan* scan) {
    const Where where = At(opcode, at);
    if (opcode == kSchema || opcode == kChannel) {
      const std::vector<uint8_t> body = RecordBody(opcode, at, size);
      Cursor cursor(body.data(), body.size(), where);
      if (opcode == kSchema) AddSchema(cursor, where, &scan->catalog);
      if (opcode == kChannel) AddChannel(cursor, where, &scan->catalog);
    } else if (opcode == kMessage) {
      if (size < kMessageHeaderSize) where.Fail("is too short for a message");
      const std::vector<uint8_t> head = file_.ReadAt(at + kRecordHeaderSize, kMessageHeaderSize);
      const auto [channel, ref] =
          MessageRef(Cursor(head.data(), head.size(), where), size, at, kUnchunked);
      scan->messages[channel].push_back(ref);
    } else if (opcode == kChunk) {
      ScanChunk(at, scan);
    }
    // Every other record (indexes, attachments, metadata, statistics) is skipped.
  }

  void ScanChunk(uint64_t chunk_at, FullScan* scan) {
    Where in_chunk = At(kChunk, 0);
    in_chunk.chunk_at = chunk_at;
    ForEachRecord(ChunkRecords(chunk_at), in_chunk, [&](const Record& record, const Where& where) {
      Cursor body(record.body, record.size, where);
      if (record.opcode == kSchema) AddSchema(body, where, &scan->catalog);
      if (record.opcode == kChannel) AddChannel(body, where, &scan->catalog);
      if (record.opcode == kMessage) {
        if (record.size < kMessageHeaderSize) where.Fail("is too short for a message");
        const auto [channel, ref] = MessageRef(body, record.size, chunk_at, record.at);
        scan->messages[channel].push_back(ref);
      }
    });
  }

  void RequireEndMagic(uint64_t footer_at) {
    const uint64_t magic_at = footer_at + kRecordHeaderSize + kFooterBodySize;
    if (!file_.Has(magic_at, kMagicSize) ||
        std::memcmp(file_.ReadAt(magic_at, kMagicSize).data(), kMagic, kMagicSize) != 0) {
      Fail("truncated: no MCAP magic after the footer at byte " + std::to_string(footer_at));
    }
  }

  void RequireKnownChannels(const FullScan& scan) const {
    for (const auto& entry : scan.messages) {
      if (scan.catalog.channels.count(entry.first) == 0) {
        Fail(std::to_string(entry.second.size()) + " messages name channel " +
             std::to_string(entry.first) + ", which no channel record defines");
      }
    }
  }

  // --- the summary section --------------------------------------------------

  // The summary, when the footer points at one whose statistics and chunk
  // index account for every message; nullopt sends readers to the full scan,
  // which then reports whatever is wrong with the file.
  std::optional<Summary> LoadSummary() {
    try {
      return ReadSummary();
    } catch (const InputError&) {
      return std::nullopt;
    }
  }

  std::optional<Summary> ReadSummary() {
    const uint64_t trailer = kRecordHeaderSize + kFooterBodySize + kMagicSize;
    if (file_.size() < kMagicSize + trailer) return std::nullopt;
    const uint64_t footer_at = file_.size() - trailer;
    const std::vector<uint8_t> footer = file_.ReadAt(footer_at, trailer);
    if (footer[0] != kFooter || LoadLittleEndian(&footer[1], 8) != kFooterBodySize ||
        std::memcmp(&footer[kRecordHeaderSize + kFooterBodySize], kMagic, kMagicSize) != 0) {
      return std::nullopt;
    }
    const uint64_t summary_at = LoadLittleEndian(&footer[kRecordHeaderSize], 8);
    if (summary_at < kMagicSize || summary_at >= footer_at) return std::nullopt;
    RequireWithinLimit(footer_at - summary_at, At(kFooter, footer_at), "a summary section");
    const std::vector<uint8_t> records = file_.ReadAt(summary_at, footer_at - summary_at);
    // The CRC covers the summary and the footer up to the CRC field; 0 = none.
    const size_t crc_at = kRecordHeaderSize + 16;
    const auto stored_crc = static_cast<uint32_t>(LoadLittleEndian(&footer[crc_at], 4));
    if (stored_crc != 0) {
      uLong crc = crc32_z(0, records.data(), records.size());
      crc = crc32_z(crc, footer.data(), crc_at);
      if (static_cast<uint32_t>(crc) != stored_crc) return std::nullopt;
    }
    Summary summary;
    bool has_statistics = false;
    uint64_t chunk_count = 0;
    ForEachRecord(records, At(kFooter, summary_at), [&](const Record& record, const Where& where) {
      Cursor body(record.body, record.size, where);
      if (record.opcode == kSchema) AddSchema(body, where, &summary.catalog);
      if (record.opcode == kChannel) AddChannel(body, where, &summary.catalog);
      if (record.opcode == kChunkIndex) summary.chunks.push_back(ReadChunkIndex(body));
      if (record.opcode == kStatistics) {
        chunk_count = ReadStatistics(body, &summary);
        has_statistics = true;
      }
    });
    if (!has_statistics || chunk_count != summary.chunks.size() || !AddsUp(summary)) {
      return std::nullopt;
    }
    std::sort(summary.chunks.begin(), summary.chunks.end(),
              [](const IndexedChunk& a, const IndexedChunk& b) { return a.at < b.at; });
    return summary;
  }

  static IndexedChunk ReadChunkIndex(Cursor body) {
    IndexedChunk chunk;
    body.U64();  // message start time
    body.U64();  // message end time
    chunk.at = body.U64();
    body.U64();  // chunk length
    Cursor offsets = body.Sub32();
    while (offsets.remaining() > 0) {
      chunk.channels.insert(offsets.U16());
      offsets.U64();  // where that channel's message index is
    }
    return chunk;
  }

  // Fills the message counts and times; returns the chunk count.
  static uint32_t ReadStatistics(Cursor body, Summary* summary) {
    summary->message_count = body.U64();
    body.U16();  // schemas
    body.U32();  // channels
    body.U32();  // attachments
    body.U32();  // metadata
    const uint32_t chunk_count = body.U32();
    summary->start_ns = static_cast<int64_t>(body.U64());
    summary->end_ns = static_cast<int64_t>(body.U64());
    Cursor counts = body.Sub32();
    while (counts.remaining() > 0) {
      const uint16_t channel = counts.U16();
      summary->message_counts[channel] = counts.U64();
    }
    return chunk_count;
  }

  // Per-channel counts that sum to the message count, for channels whose
  // schemas the summary defines.
  static bool AddsUp(const Summary& summary) {
    uint64_t total = 0;
    for (const auto& [channel, count] : summary.message_counts) {
      if (count > 0 && summary.catalog.channels.count(channel) == 0) return false;
      total += count;
    }
    for (const auto& [id, channel] : summary.catalog.channels) {
      if (channel.schema_id != 0 && summary.catalog.schemas.count(channel.schema_id) == 0) {
        return false;
      }
    }
    return total == summary.message_count;
  }

  // `channels`' messages from the chunks the index lists for them, or nullopt
  // when they are not as many as the statistics count (messages outside
  // chunks, or an index that lies).
  std::optional<std::vector<BagMessageRef>> MessagesThroughIndex(
      const std::set<uint16_t>& channels) {
    std::vector<BagMessageRef> result;
    for (const IndexedChunk& chunk : summary_->chunks) {
      if (!chunk.channels.empty() && !Overlaps(chunk.channels, channels)) continue;
      Where in_chunk = At(kChunk, 0);
      in_chunk.chunk_at = chunk.at;
      ForEachRecord(
          ChunkRecords(chunk.at), in_chunk, [&](const Record& record, const Where& where) {
            if (record.opcode != kMessage) return;
            if (record.size < kMessageHeaderSize) where.Fail("is too short for a message");
            const auto [channel, ref] = MessageRef(Cursor(record.body, record.size, where),
                                                   record.size, chunk.at, record.at);
            if (channels.count(channel) != 0) result.push_back(ref);
          });
    }
    uint64_t expected = 0;
    for (uint16_t channel : channels) {
      const auto count = summary_->message_counts.find(channel);
      if (count != summary_->message_counts.end()) expected += count->second;
    }
    if (result.size() != expected) return std::nullopt;
    SortByLogTime(&result);
    return result;
  }

  static bool Overlaps(const std::set<uint16_t>& a, const std::set<uint16_t>& b) {
    for (uint16_t id : a) {
      if (b.count(id) != 0) return true;
    }
    return false;
  }

  // --- topics and reading ---------------------------------------------------

  const Catalog& CurrentCatalog() { return summary_ ? summary_->catalog : Scanned().catalog; }

  uint64_t MessageCount(uint16_t channel) {
    if (summary_) {
      const auto count = summary_->message_counts.find(channel);
      return count == summary_->message_counts.end() ? 0 : count->second;
    }
    const auto found = Scanned().messages.find(channel);
    return found == Scanned().messages.end() ? 0 : found->second.size();
  }

  // The channel's message type: its schema's name ("" for schema id 0).
  std::string SchemaName(const Catalog& catalog, uint16_t id, const McapChannel& channel) const {
    if (channel.schema_id == 0) return "";
    const auto schema = catalog.schemas.find(channel.schema_id);
    if (schema == catalog.schemas.end()) {
      Fail("channel " + std::to_string(id) + " (" + channel.topic + ") names schema " +
           std::to_string(channel.schema_id) + ", which no schema record defines");
    }
    return schema->second.name;
  }

  void RequireCdr(const McapChannel& channel) const {
    if (channel.message_encoding != "cdr") {
      Fail("topic " + channel.topic + " is encoded as '" + channel.message_encoding +
           "'; boicp reads cdr messages only");
    }
  }

  void RequireCdrChannel(uint16_t id, const Where& where) {
    const Catalog& catalog = CurrentCatalog();
    const auto channel = catalog.channels.find(id);
    if (channel == catalog.channels.end()) {
      where.Fail("names channel " + std::to_string(id) + ", which no channel record defines");
    }
    RequireCdr(channel->second);
  }

  std::vector<uint8_t> ReadLooseMessage(uint64_t at) {
    const auto [opcode, size] = RecordHeaderAt(at);
    const Where where = At(opcode, at);
    if (opcode != kMessage) where.Fail("is where a message should be");
    if (size < kMessageHeaderSize) where.Fail("is too short for a message");
    RequireWithinLimit(size - kMessageHeaderSize, where, "a message");
    std::vector<uint8_t> body = file_.ReadAt(at + kRecordHeaderSize, size);
    RequireCdrChannel(static_cast<uint16_t>(LoadLittleEndian(body.data(), 2)), where);
    body.erase(body.begin(), body.begin() + kMessageHeaderSize);
    return body;
  }

  std::vector<uint8_t> ReadChunkedMessage(uint64_t chunk_at, uint64_t offset) {
    const std::vector<uint8_t>& records = ChunkRecords(chunk_at);
    Where where = At(kMessage, offset);
    where.chunk_at = chunk_at;
    if (offset >= records.size() || records.size() - offset < kRecordHeaderSize) {
      where.Fail("lies past the end of the chunk (" + std::to_string(records.size()) + " bytes)");
    }
    const uint64_t size = LoadLittleEndian(&records[offset + 1], 8);
    if (records[offset] != kMessage) where.Fail("is not a message");
    if (size > records.size() - offset - kRecordHeaderSize || size < kMessageHeaderSize) {
      where.Fail("declares " + std::to_string(size) + " bytes, which do not fit its chunk");
    }
    const uint8_t* body = &records[offset + kRecordHeaderSize];
    RequireCdrChannel(static_cast<uint16_t>(LoadLittleEndian(body, 2)), where);
    return {body + kMessageHeaderSize, body + size};
  }

  std::string path_;
  BagLimits limits_;
  BoundedFile file_;
  std::optional<Summary> summary_;
  std::optional<FullScan> scan_;
  uint64_t cached_chunk_at_ = kUnchunked;
  std::vector<uint8_t> cached_chunk_;
};

}  // namespace
}  // namespace mcap_bag

std::unique_ptr<BagReader> OpenMcapBag(const std::string& path, const BagLimits& limits) {
  return std::make_unique<mcap_bag::McapBag>(path, limits);
}

}  // namespace boicp::io_detail
