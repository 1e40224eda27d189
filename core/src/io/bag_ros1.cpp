// ROS 1 bags (format 2.0), read by our own bounded parser.
//
// rosbag_storage (the ROS reference reader) trusts the file: it allocates
// whatever size a record declares, parses record headers in a decompressed
// chunk without bounds (a crafted lz4 or bz2 chunk makes ros::Header::parse
// read past the heap buffer), dereferences unknown connection ids, logs to
// stderr through console_bridge and dlopens an encryption plugin (gpgme,
// libcrypto) for every Bag. So this reader walks the format itself: the
// version line, the file header, the connection and chunk-info records at
// index_pos, each chunk's header and the index records after it (what
// rosbag::Bag::open reads), then, in Read, one chunk decompressed with bzip2
// or LZ4F and one message record. Every size is checked against the file,
// the chunk and BagLimits before it is used.
//
// A BagMessageRef from this reader: position = the connection id, offset =
// the message's ordinal among that connection's messages logged at exactly
// log_time_ns (equal times in bag order, as rosbag keeps them). A fresh
// reader finds it in the index it built when opening. size is an upper
// bound: the index does not store sizes, so it is the distance to the next
// indexed record of the chunk (or the chunk's end) less the 8 bytes of
// record lengths (it can take in a connection record written in the chunk).

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bag_readers.hpp"
#include "boicp/util/types.hpp"
#include "bounded_file.hpp"
#include "chunk_decompression.hpp"

namespace boicp::io_detail {
// Named, so that a unity batch holding another bag reader sees no clash.
namespace ros1_bag {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr uint64_t kMagicBytes = sizeof kMagic - 1;

// Record ops (rosbag/constants.h).
constexpr uint8_t kOpMessageData = 0x02;
constexpr uint8_t kOpFileHeader = 0x03;
constexpr uint8_t kOpIndexData = 0x04;
constexpr uint8_t kOpChunk = 0x05;
constexpr uint8_t kOpChunkInfo = 0x06;
constexpr uint8_t kOpConnection = 0x07;

// ros::Header::parse refuses (and logs to stderr) a field over this.
constexpr uint32_t kMaxHeaderField = 1000000;

// The smallest record: header length and data length.
constexpr uint64_t kRecordLengths = 8;

using Fields = std::map<std::string, std::string>;

/// A bag file read by explicit ranges, every range checked against the
/// file's size and the message limit.
class BagFile {
 public:
  BagFile(const std::string& path, const BagLimits& limits) : file_(path), limits_(limits) {}

  uint64_t size() const { return file_.size(); }
  const BagLimits& limits() const { return limits_; }

  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(file_.path() + ": " + problem);
  }

  /// `n` bytes at `at`: refused when past the end of the file or over the
  /// message limit, so nothing is allocated from a size the file made up.
  std::vector<uint8_t> Read(uint64_t at, uint64_t n, const char* what) {
    if (!file_.Has(at, n)) {
      Fail(std::string("truncated ") + what + " at byte " + std::to_string(at) + " (" +
           std::to_string(n) + " bytes past the end of the " + std::to_string(size()) +
           "-byte file)");
    }
    if (n > limits_.max_message_bytes) {
      Fail(std::string(what) + " at byte " + std::to_string(at) + " declares " + std::to_string(n) +
           " bytes, over the limit of " + std::to_string(limits_.max_message_bytes));
    }
    return file_.ReadAt(at, n);
  }

  uint32_t U32(uint64_t at, const char* what) {
    return static_cast<uint32_t>(LoadLittleEndian(Read(at, 4, what).data(), 4));
  }

 private:
  BoundedFile file_;
  BagLimits limits_;
};

// A record header's fields, each a uint32 length then "name=value", checked
// the way ros::Header::parse reads them but without reading past the header.
Fields ParseFields(BagFile& file, const uint8_t* p, uint64_t n, uint64_t at, const char* what) {
  Fields fields;
  uint64_t used = 0;
  while (used < n) {
    if (n - used < 4)
      file.Fail(std::string("malformed ") + what + " header at byte " + std::to_string(at));
    const uint64_t length = LoadLittleEndian(p + used, 4);
    used += 4;
    if (length > n - used || length > kMaxHeaderField) {
      file.Fail(std::string("malformed ") + what + " header at byte " + std::to_string(at) +
                " (a field overruns it)");
    }
    const std::string line(reinterpret_cast<const char*>(p + used), length);
    used += length;
    const size_t equals = line.find('=');
    if (equals == std::string::npos) {
      file.Fail(std::string("malformed ") + what + " header at byte " + std::to_string(at) +
                " (a field without '=')");
    }
    fields[line.substr(0, equals)] = line.substr(equals + 1);  // the last one wins, as in ROS
  }
  return fields;
}

// One record: its header fields and where its data lies.
struct Record {
  Fields fields;
  uint64_t data_at = 0;
  uint32_t data_bytes = 0;
  uint64_t end = 0;
};

Record ReadRecord(BagFile& file, uint64_t at, const char* what) {
  Record record;
  const uint32_t header_bytes = file.U32(at, what);
  const std::vector<uint8_t> header = file.Read(at + 4, header_bytes, what);
  record.fields = ParseFields(file, header.data(), header.size(), at, what);
  record.data_bytes = file.U32(at + 4 + header_bytes, what);
  record.data_at = at + kRecordLengths + header_bytes;
  if (record.data_bytes > file.size() - record.data_at) {
    file.Fail(std::string("truncated ") + what + " at byte " + std::to_string(at));
  }
  record.end = record.data_at + record.data_bytes;
  return record;
}

// A fixed-size field, as rosbag's readField<T> insists.
uint64_t UnsignedField(BagFile& file, const Fields& fields, const char* name, size_t bytes,
                       const char* what) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != bytes) {
    file.Fail(std::string(what) + " has no " + std::to_string(bytes) + "-byte '" + name +
              "' field");
  }
  return LoadLittleEndian(reinterpret_cast<const uint8_t*>(it->second.data()), bytes);
}

std::string StringField(BagFile& file, const Fields& fields, const char* name, const char* what) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.empty()) {
    file.Fail(std::string(what) + " has no '" + name + "' field");
  }
  return it->second;
}

void RequireOp(BagFile& file, const Record& record, uint8_t op, const char* what) {
  if (UnsignedField(file, record.fields, "op", 1, what) != op) {
    file.Fail(std::string("expected a ") + what + " record at byte " +
              std::to_string(record.data_at));
  }
}

struct Connection {
  std::string topic;
  std::string type;
};

// One indexed message.
struct Entry {
  int64_t time_ns = 0;
  uint32_t sec = 0;
  uint32_t nsec = 0;
  uint64_t chunk_pos = 0;
  uint32_t offset = 0;      // of its record in the decompressed chunk
  uint64_t size_bound = 0;  // see the file comment
};

struct Chunk {
  std::string compression;
  uint64_t data_at = 0;  // the chunk's (compressed) bytes in the file
  uint32_t stored_bytes = 0;
  uint32_t bytes = 0;  // decompressed
};

/// A bag's index, checked: connections by id, each connection's messages
/// in rosbag's order (time, then bag order), chunks by position.
struct Ros1Index {
  std::map<uint32_t, Connection> connections;
  std::map<uint32_t, std::vector<Entry>> entries;
  std::map<uint64_t, Chunk> chunks;
};

struct FileHeader {
  uint64_t index_at = 0;
  uint32_t connections = 0;
  uint32_t chunks = 0;
};

FileHeader ReadFileHeader(BagFile& file) {
  const std::vector<uint8_t> magic =
      file.Read(0, std::min<uint64_t>(kMagicBytes, file.size()), "version line");
  if (magic.size() < kMagicBytes || std::memcmp(magic.data(), kMagic, kMagicBytes) != 0) {
    const bool ros1_bag = magic.size() >= 9 && std::memcmp(magic.data(), "#ROSBAG V", 9) == 0;
    file.Fail(ros1_bag ? "unsupported ROS 1 bag version (boicp reads format 2.0)"
                       : "not a ROS 1 bag (no '#ROSBAG V2.0' line)");
  }
  const Record record = ReadRecord(file, kMagicBytes, "file header");
  RequireOp(file, record, kOpFileHeader, "file header");
  // rosbag's AES encryption plugin writes this field; its chunks are unreadable here.
  if (record.fields.count("encryptor") != 0) file.Fail("encrypted bags are not supported");
  FileHeader header;
  header.index_at = UnsignedField(file, record.fields, "index_pos", 8, "file header");
  header.connections =
      static_cast<uint32_t>(UnsignedField(file, record.fields, "conn_count", 4, "file header"));
  header.chunks =
      static_cast<uint32_t>(UnsignedField(file, record.fields, "chunk_count", 4, "file header"));
  if (header.index_at == 0) {
    file.Fail("the bag has no index (recording was interrupted; run 'rosbag reindex')");
  }
  if (header.index_at < record.end || header.index_at > file.size()) {
    file.Fail("the index position " + std::to_string(header.index_at) + " is outside the file");
  }
  return header;
}

uint64_t ReadConnection(BagFile& file, uint64_t at, Ros1Index& index) {
  const Record record = ReadRecord(file, at, "connection");
  RequireOp(file, record, kOpConnection, "connection");
  const auto id =
      static_cast<uint32_t>(UnsignedField(file, record.fields, "conn", 4, "connection"));
  Connection connection;
  connection.topic = StringField(file, record.fields, "topic", "connection");
  // The data is the connection header's fields (type, md5sum, definition).
  const std::vector<uint8_t> data = file.Read(record.data_at, record.data_bytes, "connection");
  const Fields header = ParseFields(file, data.data(), data.size(), at, "connection");
  const auto type = header.find("type");
  connection.type = type == header.end() ? "" : type->second;
  index.connections.emplace(id, std::move(connection));  // rosbag keeps the first of an id
  return record.end;
}

// A chunk-info record: where a chunk is and which connections it holds.
struct ChunkInfo {
  uint64_t chunk_pos = 0;
  size_t connections = 0;  // distinct ids: one index record per id follows the chunk
};

uint64_t ReadChunkInfo(BagFile& file, uint64_t at, std::vector<ChunkInfo>& infos) {
  const Record record = ReadRecord(file, at, "chunk info");
  RequireOp(file, record, kOpChunkInfo, "chunk info");
  if (UnsignedField(file, record.fields, "ver", 4, "chunk info") != 1) {
    file.Fail("unsupported chunk info version at byte " + std::to_string(at));
  }
  ChunkInfo info;
  info.chunk_pos = UnsignedField(file, record.fields, "chunk_pos", 8, "chunk info");
  UnsignedField(file, record.fields, "start_time", 8, "chunk info");
  UnsignedField(file, record.fields, "end_time", 8, "chunk info");
  const uint64_t count = UnsignedField(file, record.fields, "count", 4, "chunk info");
  // rosbag reads count pairs whatever the data length says; refuse when they differ.
  if (record.data_bytes != 8 * count)
    file.Fail("malformed chunk info at byte " + std::to_string(at));
  const std::vector<uint8_t> data = file.Read(record.data_at, record.data_bytes, "chunk info");
  std::vector<uint32_t> ids;
  for (uint64_t i = 0; i < count; ++i) {
    ids.push_back(static_cast<uint32_t>(LoadLittleEndian(data.data() + 8 * i, 4)));
  }
  std::sort(ids.begin(), ids.end());
  info.connections = static_cast<size_t>(std::unique(ids.begin(), ids.end()) - ids.begin());
  infos.push_back(info);
  return record.end;
}

Chunk ReadChunkHeader(BagFile& file, uint64_t at) {
  const Record record = ReadRecord(file, at, "chunk");
  RequireOp(file, record, kOpChunk, "chunk");
  Chunk chunk;
  chunk.compression = StringField(file, record.fields, "compression", "chunk");
  chunk.bytes = static_cast<uint32_t>(UnsignedField(file, record.fields, "size", 4, "chunk"));
  chunk.data_at = record.data_at;
  chunk.stored_bytes = record.data_bytes;
  if (chunk.compression != "none" && chunk.compression != "bz2" && chunk.compression != "lz4") {
    file.Fail("chunk at byte " + std::to_string(at) + " has unsupported compression '" +
              chunk.compression + "' (none, bz2 or lz4)");
  }
  // An uncompressed chunk's two sizes must agree (rosbag reads the stored one).
  if (chunk.compression == "none" && chunk.bytes != chunk.stored_bytes) {
    file.Fail("uncompressed chunk at byte " + std::to_string(at) + " has two sizes");
  }
  if (chunk.bytes > file.limits().max_message_bytes) {
    file.Fail("chunk at byte " + std::to_string(at) + " decompresses to " +
              std::to_string(chunk.bytes) + " bytes, over the limit of " +
              std::to_string(file.limits().max_message_bytes));
  }
  return chunk;
}

// An index-data record after a chunk: one connection's messages in it.
uint64_t ReadIndexData(BagFile& file, uint64_t at, uint64_t chunk_pos, const Chunk& chunk,
                       Ros1Index& index) {
  const Record record = ReadRecord(file, at, "index");
  RequireOp(file, record, kOpIndexData, "index");
  if (UnsignedField(file, record.fields, "ver", 4, "index") != 1) {
    file.Fail("unsupported index version at byte " + std::to_string(at));
  }
  const auto id = static_cast<uint32_t>(UnsignedField(file, record.fields, "conn", 4, "index"));
  const uint64_t count = UnsignedField(file, record.fields, "count", 4, "index");
  if (index.connections.count(id) == 0) {
    file.Fail("index at byte " + std::to_string(at) + " names unknown connection " +
              std::to_string(id));
  }
  if (record.data_bytes != 12 * count) file.Fail("malformed index at byte " + std::to_string(at));
  const std::vector<uint8_t> data = file.Read(record.data_at, record.data_bytes, "index");
  std::vector<Entry>& entries = index.entries[id];
  for (uint64_t i = 0; i < count; ++i) {
    Entry entry;
    entry.sec = static_cast<uint32_t>(LoadLittleEndian(data.data() + 12 * i, 4));
    entry.nsec = static_cast<uint32_t>(LoadLittleEndian(data.data() + 12 * i + 4, 4));
    entry.offset = static_cast<uint32_t>(LoadLittleEndian(data.data() + 12 * i + 8, 4));
    entry.chunk_pos = chunk_pos;
    // rosbag drops (and logs) times outside ros::TIME_MIN..TIME_MAX and
    // normalises nsec over a second: neither is a time a recorder writes.
    if (entry.nsec > 999999999 || (entry.sec == 0 && entry.nsec == 0)) {
      file.Fail("index at byte " + std::to_string(at) + " holds an invalid time");
    }
    if (uint64_t{entry.offset} + kRecordLengths > chunk.bytes) {
      file.Fail("index at byte " + std::to_string(at) + " points past its chunk");
    }
    entry.time_ns = int64_t{entry.sec} * 1000000000 + entry.nsec;
    entries.push_back(entry);
  }
  return record.end;
}

uint64_t ReadChunkAndIndexes(BagFile& file, const ChunkInfo& info, Ros1Index& index) {
  if (info.chunk_pos < kMagicBytes || info.chunk_pos >= file.size()) {
    file.Fail("a chunk position " + std::to_string(info.chunk_pos) + " is outside the file");
  }
  const Chunk chunk = ReadChunkHeader(file, info.chunk_pos);
  index.chunks.emplace(info.chunk_pos, chunk);
  uint64_t at = chunk.data_at + chunk.stored_bytes;
  for (size_t i = 0; i < info.connections; ++i)
    at = ReadIndexData(file, at, info.chunk_pos, chunk, index);
  return at;
}

// Each message's size bound: up to the next indexed record of its chunk.
void BoundMessageSizes(Ros1Index& index) {
  std::map<uint64_t, std::vector<uint32_t>> offsets;
  for (const auto& [id, entries] : index.entries) {
    for (const Entry& entry : entries) offsets[entry.chunk_pos].push_back(entry.offset);
  }
  for (auto& [pos, list] : offsets) std::sort(list.begin(), list.end());
  for (auto& [id, entries] : index.entries) {
    for (Entry& entry : entries) {
      const std::vector<uint32_t>& list = offsets[entry.chunk_pos];
      const auto next = std::upper_bound(list.begin(), list.end(), entry.offset);
      const uint64_t end = next == list.end() ? index.chunks[entry.chunk_pos].bytes : *next;
      // Two records cannot start closer than their 8 bytes of lengths.
      entry.size_bound =
          end >= entry.offset + kRecordLengths ? end - entry.offset - kRecordLengths : 0;
    }
  }
}

Ros1Index ReadIndex(BagFile& file) {
  const FileHeader header = ReadFileHeader(file);
  Ros1Index index;
  uint64_t at = header.index_at;
  for (uint32_t i = 0; i < header.connections; ++i) at = ReadConnection(file, at, index);
  std::vector<ChunkInfo> infos;
  for (uint32_t i = 0; i < header.chunks; ++i) at = ReadChunkInfo(file, at, infos);
  for (const ChunkInfo& info : infos) ReadChunkAndIndexes(file, info, index);
  // rosbag's per-connection multiset: by time, equal times in insertion order.
  for (auto& [id, entries] : index.entries) {
    std::stable_sort(entries.begin(), entries.end(),
                     [](const Entry& a, const Entry& b) { return a.time_ns < b.time_ns; });
  }
  BoundMessageSizes(index);
  return index;
}

// A chunk's decompressed bytes, exactly its declared size (checked against
// BagLimits when indexing, so this allocation is bounded).
std::vector<uint8_t> ReadChunk(BagFile& file, const Chunk& chunk) {
  std::vector<uint8_t> stored = file.Read(chunk.data_at, chunk.stored_bytes, "chunk");
  if (chunk.compression == "none" || chunk.bytes == 0) return stored;
  // rosbag's lz4 chunks are standard LZ4 frames (roslz4 writes the frame format).
  try {
    return DecompressChunk(chunk.compression == "bz2" ? ChunkCodec::kBzip2 : ChunkCodec::kLz4Frame,
                           stored, chunk.bytes);
  } catch (const InputError& e) {
    file.Fail(chunk.compression + " chunk " + e.what());
  }
}

// The data of the message record at `offset` in a decompressed chunk: a
// header that fits and parses, the MSG_DATA op of the expected connection,
// and data inside the chunk.
std::vector<uint8_t> MessageData(BagFile& file, const std::vector<uint8_t>& chunk, uint32_t offset,
                                 uint32_t connection) {
  const std::string where = "message record at chunk byte " + std::to_string(offset);
  if (uint64_t{offset} + kRecordLengths > chunk.size()) file.Fail(where + " is past its chunk");
  const uint8_t* record = chunk.data() + offset;
  const uint64_t room = chunk.size() - offset - kRecordLengths;
  const uint64_t header_bytes = LoadLittleEndian(record, 4);
  if (header_bytes > room) file.Fail(where + " overruns its chunk");
  const Fields fields = ParseFields(file, record + 4, header_bytes, offset, "message");
  if (UnsignedField(file, fields, "op", 1, "message") != kOpMessageData ||
      UnsignedField(file, fields, "conn", 4, "message") != connection) {
    file.Fail(where + " is not a message of connection " + std::to_string(connection));
  }
  const uint64_t data_bytes = LoadLittleEndian(record + 4 + header_bytes, 4);
  if (data_bytes > room - header_bytes) file.Fail(where + " overruns its chunk");
  const uint8_t* data = record + kRecordLengths + header_bytes;
  return {data, data + data_bytes};
}

class Ros1Bag final : public BagReader {
 public:
  Ros1Bag(std::string path, BagFile file, Ros1Index index)
      : path_(std::move(path)), file_(std::move(file)), index_(std::move(index)) {}

  const std::string& path() const override { return path_; }
  BagStorage storage() const override { return BagStorage::kRos1; }
  MessageEncoding encoding() const override { return MessageEncoding::kRos1; }

  std::vector<BagTopic> Topics() override {
    std::map<std::string, BagTopic> topics;
    for (const auto& [id, connection] : index_.connections) {
      BagTopic& topic = topics[connection.topic];
      if (topic.name.empty()) topic = {connection.topic, connection.type, 0};
      const auto entries = index_.entries.find(id);
      if (entries != index_.entries.end()) topic.messages += entries->second.size();
    }
    std::vector<BagTopic> result;
    for (auto& [name, topic] : topics) result.push_back(std::move(topic));
    return result;
  }

  std::pair<int64_t, int64_t> TimeRange() override {
    bool any = false;
    std::pair<int64_t, int64_t> range{0, 0};
    for (const auto& [id, entries] : index_.entries) {
      if (entries.empty()) continue;
      const int64_t first = entries.front().time_ns;
      const int64_t last = entries.back().time_ns;
      range = any ? std::make_pair(std::min(range.first, first), std::max(range.second, last))
                  : std::make_pair(first, last);
      any = true;
    }
    return range;
  }

  std::vector<BagMessageRef> Messages(const std::string& topic) override {
    struct Located {
      BagMessageRef ref;
      uint64_t chunk_pos;
      uint32_t offset;
    };
    std::vector<Located> located;
    for (const auto& [id, connection] : index_.connections) {
      if (connection.topic != topic) continue;
      const auto found = index_.entries.find(id);
      if (found == index_.entries.end()) continue;
      const std::vector<Entry>& entries = found->second;
      uint64_t ordinal = 0;
      for (size_t i = 0; i < entries.size(); ++i) {
        ordinal = (i > 0 && entries[i - 1].time_ns == entries[i].time_ns) ? ordinal + 1 : 0;
        const Entry& e = entries[i];
        located.push_back({{e.time_ns, id, ordinal, e.size_bound}, e.chunk_pos, e.offset});
      }
    }
    // Ties between connections in the bag's order: chunk, then place in it.
    std::stable_sort(located.begin(), located.end(), [](const Located& a, const Located& b) {
      return std::tie(a.ref.log_time_ns, a.chunk_pos, a.offset) <
             std::tie(b.ref.log_time_ns, b.chunk_pos, b.offset);
    });
    std::vector<BagMessageRef> refs;
    refs.reserve(located.size());
    for (const Located& l : located) refs.push_back(l.ref);
    return refs;
  }

  std::vector<uint8_t> Read(const BagMessageRef& message) override {
    const Entry& entry = FindEntry(message);
    // Consecutive reads mostly fall in one chunk: keep the last one.
    if (cached_chunk_pos_ != entry.chunk_pos) {
      cached_chunk_.clear();
      cached_chunk_ = ReadChunk(file_, index_.chunks.at(entry.chunk_pos));
      cached_chunk_pos_ = entry.chunk_pos;
    }
    return MessageData(file_, cached_chunk_, entry.offset, static_cast<uint32_t>(message.position));
  }

 private:
  const Entry& FindEntry(const BagMessageRef& message) const {
    const auto found = message.position <= UINT32_MAX
                           ? index_.entries.find(static_cast<uint32_t>(message.position))
                           : index_.entries.end();
    if (found != index_.entries.end()) {
      const std::vector<Entry>& entries = found->second;
      Entry key;
      key.time_ns = message.log_time_ns;
      const auto range =
          std::equal_range(entries.begin(), entries.end(), key,
                           [](const Entry& a, const Entry& b) { return a.time_ns < b.time_ns; });
      if (message.offset < static_cast<uint64_t>(range.second - range.first)) {
        return *(range.first + static_cast<std::ptrdiff_t>(message.offset));
      }
    }
    throw InputError(path_ + ": no message of connection " + std::to_string(message.position) +
                     " logged at " + std::to_string(message.log_time_ns) + " ns");
  }

  std::string path_;
  BagFile file_;
  Ros1Index index_;
  uint64_t cached_chunk_pos_ = UINT64_MAX;
  std::vector<uint8_t> cached_chunk_;
};

}  // namespace
}  // namespace ros1_bag

std::unique_ptr<BagReader> OpenRos1Bag(const std::string& path, const BagLimits& limits) {
  ros1_bag::BagFile file(path, limits);
  ros1_bag::Ros1Index index = ros1_bag::ReadIndex(file);
  return std::make_unique<ros1_bag::Ros1Bag>(path, std::move(file), std::move(index));
}

}  // namespace boicp::io_detail
