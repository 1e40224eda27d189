#include "ros2_bag_writer.hpp"

#include <lz4frame.h>
#include <sqlite3.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <stdexcept>

namespace boicp::test {
namespace {

namespace fs = std::filesystem;

// rosbag2's sqlite3 schema as Humble writes it.
constexpr const char* kRosbag2Schema =
    "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
    "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
    "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
    "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);";

size_t TopicIndex(const BagTestContents& contents, const std::string& name) {
  for (size_t i = 0; i < contents.topics.size(); ++i) {
    if (contents.topics[i].name == name) return i;
  }
  throw std::invalid_argument("test bag: message on unlisted topic " + name);
}

// --- sqlite ------------------------------------------------------------------

void Check(sqlite3* db, int status, const char* doing) {
  if (status != SQLITE_OK && status != SQLITE_DONE) {
    throw std::runtime_error(std::string("test bag: ") + doing + ": " + sqlite3_errmsg(db));
  }
}

void Exec(sqlite3* db, const std::string& sql) {
  Check(db, sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), sql.c_str());
}

void InsertTopics(sqlite3* db, const BagTestContents& contents) {
  sqlite3_stmt* insert = nullptr;
  Check(db,
        sqlite3_prepare_v2(db, "INSERT INTO topics VALUES (?, ?, ?, ?, '')", -1, &insert, nullptr),
        "preparing");
  for (size_t i = 0; i < contents.topics.size(); ++i) {
    const BagTestTopic& topic = contents.topics[i];
    sqlite3_bind_int64(insert, 1, static_cast<sqlite3_int64>(i + 1));
    sqlite3_bind_text(insert, 2, topic.name.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(insert, 3, topic.type.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(insert, 4, topic.format.c_str(), -1, SQLITE_TRANSIENT);
    Check(db, sqlite3_step(insert), "inserting a topic");
    sqlite3_reset(insert);
  }
  sqlite3_finalize(insert);
}

void InsertMessages(sqlite3* db, const BagTestContents& contents) {
  sqlite3_stmt* insert = nullptr;
  Check(db,
        sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)",
                           -1, &insert, nullptr),
        "preparing");
  for (const BagTestMessage& message : contents.messages) {
    sqlite3_bind_int64(insert, 1,
                       static_cast<sqlite3_int64>(TopicIndex(contents, message.topic) + 1));
    sqlite3_bind_int64(insert, 2, message.log_time_ns);
    // A zero-length blob must still be a blob, not NULL (the column is NOT NULL).
    static const uint8_t kNothing = 0;
    sqlite3_bind_blob(insert, 3, message.data.empty() ? &kNothing : message.data.data(),
                      static_cast<int>(message.data.size()), SQLITE_TRANSIENT);
    Check(db, sqlite3_step(insert), "inserting a message");
    sqlite3_reset(insert);
  }
  sqlite3_finalize(insert);
}

// --- metadata.yaml -----------------------------------------------------------

// The first and last log time of the messages; {0, 0} for none.
std::pair<int64_t, int64_t> LogTimeSpan(const BagTestContents& contents) {
  int64_t start = 0;
  int64_t end = 0;
  for (size_t i = 0; i < contents.messages.size(); ++i) {
    const int64_t t = contents.messages[i].log_time_ns;
    start = i == 0 ? t : std::min(start, t);
    end = i == 0 ? t : std::max(end, t);
  }
  return {start, end};
}

std::string MetadataYaml(const BagTestContents& contents, const std::string& storage,
                         const std::string& file_name) {
  const auto [start, end] = LogTimeSpan(contents);
  const std::string count = std::to_string(contents.messages.size());
  std::string yaml =
      "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: " + storage +
      "\n  duration:\n    nanoseconds: " + std::to_string(end - start) +
      "\n  starting_time:\n    nanoseconds_since_epoch: " + std::to_string(start) +
      "\n  message_count: " + count + "\n  topics_with_message_count:\n";
  for (const BagTestTopic& topic : contents.topics) {
    const auto messages =
        std::count_if(contents.messages.begin(), contents.messages.end(),
                      [&](const BagTestMessage& m) { return m.topic == topic.name; });
    yaml +=
        "    - topic_metadata:\n        name: " + topic.name + "\n        type: " + topic.type +
        "\n        serialization_format: " + topic.format +
        "\n        offered_qos_profiles: \"\"\n      message_count: " + std::to_string(messages) +
        "\n";
  }
  yaml += "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - " +
          file_name + "\n  files:\n    - path: " + file_name +
          "\n      starting_time:\n        nanoseconds_since_epoch: " + std::to_string(start) +
          "\n      duration:\n        nanoseconds: " + std::to_string(end - start) +
          "\n      message_count: " + count + "\n";
  return yaml;
}

// --- mcap --------------------------------------------------------------------

std::string Bytes(const std::vector<uint8_t>& data) { return {data.begin(), data.end()}; }

std::string Compress(McapCompression compression, const std::string& records) {
  switch (compression) {
    case McapCompression::kNone:
      return records;
    case McapCompression::kZstd:
      return mcap::Zstd(records);
    case McapCompression::kLz4:
      return mcap::Lz4Frame(records);
  }
  return records;
}

std::string CompressionName(McapCompression compression) {
  switch (compression) {
    case McapCompression::kNone:
      return "";
    case McapCompression::kZstd:
      return "zstd";
    case McapCompression::kLz4:
      return "lz4";
  }
  return "";
}

// Schema ids by type (from 1, in topic order) and what each topic's channel
// (id = topic index + 1) needs written before its first message.
struct McapIds {
  std::map<std::string, uint16_t> schema_of_type;
  std::vector<uint16_t> schema_of_topic;
};

McapIds AssignIds(const BagTestContents& contents) {
  McapIds ids;
  for (const BagTestTopic& topic : contents.topics) {
    const auto added = ids.schema_of_type.emplace(
        topic.type, static_cast<uint16_t>(ids.schema_of_type.size() + 1));
    ids.schema_of_topic.push_back(added.first->second);
  }
  return ids;
}

std::string TopicRecords(const BagTestContents& contents, const McapIds& ids, size_t topic,
                         std::set<uint16_t>* schemas_written) {
  std::string records;
  const uint16_t schema = ids.schema_of_topic[topic];
  if (schemas_written->insert(schema).second) {
    records += mcap::Schema(schema, contents.topics[topic].type);
  }
  records += mcap::Channel(static_cast<uint16_t>(topic + 1), schema, contents.topics[topic].name,
                           contents.topics[topic].format);
  return records;
}

struct ChunkWriter {
  const BagTestContents& contents;
  const McapIds& ids;
  const McapWriteOptions& options;
  std::string* out;
  std::set<uint16_t> schemas_written;
  std::set<size_t> channels_written;
  std::string chunk_indexes;

  // Writes messages [first, last) as one chunk and its message indexes.
  uint64_t Write(size_t first, size_t last) {
    std::string records;
    std::map<uint16_t, std::string> index_entries;
    int64_t start = contents.messages[first].log_time_ns;
    int64_t end = start;
    for (size_t i = first; i < last; ++i) {
      const BagTestMessage& message = contents.messages[i];
      const size_t topic = TopicIndex(contents, message.topic);
      if (channels_written.insert(topic).second) {
        records += TopicRecords(contents, ids, topic, &schemas_written);
      }
      const auto channel = static_cast<uint16_t>(topic + 1);
      index_entries[channel] +=
          mcap::U64(static_cast<uint64_t>(message.log_time_ns)) + mcap::U64(records.size());
      records += mcap::Message(channel, message.log_time_ns, Bytes(message.data));
      start = std::min(start, message.log_time_ns);
      end = std::max(end, message.log_time_ns);
    }
    const std::string compressed = Compress(options.compression, records);
    const uint64_t chunk_at = out->size();
    const std::string chunk = mcap::Chunk(CompressionName(options.compression), compressed,
                                          records.size(), mcap::Crc32(records));
    *out += chunk;
    std::string offsets;
    const uint64_t indexes_at = out->size();
    for (const auto& [channel, entries] : index_entries) {
      offsets += mcap::U16(channel) + mcap::U64(out->size());
      *out += mcap::Record(
          0x07, mcap::U16(channel) + mcap::U32(static_cast<uint32_t>(entries.size())) + entries);
    }
    chunk_indexes += mcap::Record(
        0x08, mcap::U64(static_cast<uint64_t>(start)) + mcap::U64(static_cast<uint64_t>(end)) +
                  mcap::U64(chunk_at) + mcap::U64(chunk.size()) +
                  mcap::U32(static_cast<uint32_t>(offsets.size())) + offsets +
                  mcap::U64(out->size() - indexes_at) +
                  mcap::Str(CompressionName(options.compression)) + mcap::U64(compressed.size()) +
                  mcap::U64(records.size()));
    return chunk_at;
  }
};

std::string Statistics(const BagTestContents& contents, const McapIds& ids, size_t chunks) {
  std::map<uint16_t, uint64_t> counts;
  const auto [start, end] = LogTimeSpan(contents);
  for (const BagTestMessage& message : contents.messages) {
    ++counts[static_cast<uint16_t>(TopicIndex(contents, message.topic) + 1)];
  }
  std::string count_map;
  for (const auto& [channel, count] : counts) count_map += mcap::U16(channel) + mcap::U64(count);
  return mcap::Record(
      0x0B, mcap::U64(contents.messages.size()) +
                mcap::U16(static_cast<uint16_t>(ids.schema_of_type.size())) +
                mcap::U32(static_cast<uint32_t>(contents.topics.size())) + mcap::U32(0) +
                mcap::U32(0) + mcap::U32(static_cast<uint32_t>(chunks)) +
                mcap::U64(static_cast<uint64_t>(start)) + mcap::U64(static_cast<uint64_t>(end)) +
                mcap::U32(static_cast<uint32_t>(count_map.size())) + count_map);
}

std::string SummaryOffset(uint8_t opcode, uint64_t start, uint64_t length) {
  return mcap::Record(
      0x0E, std::string(1, static_cast<char>(opcode)) + mcap::U64(start) + mcap::U64(length));
}

}  // namespace

void WriteBytes(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("test bag: cannot write " + file.string());
}

std::string ReadBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path WriteRos2SqliteBag(const fs::path& folder, const BagTestContents& contents,
                            int page_size) {
  fs::create_directories(folder);
  const std::string file_name = folder.filename().string() + "_0.db3";
  const fs::path db_path = folder / file_name;
  fs::remove(db_path);
  sqlite3* db = nullptr;
  const int opened = sqlite3_open_v2(db_path.string().c_str(), &db,
                                     SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  try {
    Check(db, opened, "creating the database");
    Exec(db, "PRAGMA page_size=" + std::to_string(page_size) + ";");
    Exec(db, kRosbag2Schema);
    Exec(db, "BEGIN;");
    InsertTopics(db, contents);
    InsertMessages(db, contents);
    Exec(db, "COMMIT;");
  } catch (...) {
    sqlite3_close(db);
    throw;
  }
  sqlite3_close(db);
  WriteBytes(folder / "metadata.yaml", MetadataYaml(contents, "sqlite3", file_name));
  return db_path;
}

void SetWalMode(const fs::path& db3) {
  sqlite3* db = nullptr;
  const int opened = sqlite3_open_v2(db3.string().c_str(), &db, SQLITE_OPEN_READWRITE, nullptr);
  try {
    Check(db, opened, "opening the database");
    Exec(db, "PRAGMA journal_mode=WAL;");
  } catch (...) {
    sqlite3_close(db);
    throw;
  }
  sqlite3_close(db);  // the last connection checkpoints and removes the -wal file
}

McapLayout WriteMcap(const fs::path& file, const BagTestContents& contents,
                     const McapWriteOptions& options) {
  const McapIds ids = AssignIds(contents);
  McapLayout layout;
  std::string out = mcap::Magic() + mcap::Header();
  ChunkWriter chunks{contents, ids, options, &out, {}, {}, {}};
  if (options.chunked) {
    // Topics without messages get their records before the first chunk.
    for (size_t topic = 0; topic < contents.topics.size(); ++topic) {
      const bool has_messages = std::any_of(
          contents.messages.begin(), contents.messages.end(),
          [&](const BagTestMessage& m) { return m.topic == contents.topics[topic].name; });
      if (!has_messages && chunks.channels_written.insert(topic).second) {
        out += TopicRecords(contents, ids, topic, &chunks.schemas_written);
      }
    }
    const size_t per_chunk = std::max<size_t>(options.messages_per_chunk, 1);
    for (size_t first = 0; first < contents.messages.size(); first += per_chunk) {
      layout.chunk_offsets.push_back(
          chunks.Write(first, std::min(first + per_chunk, contents.messages.size())));
    }
  } else {
    std::set<uint16_t> schemas_written;
    for (size_t topic = 0; topic < contents.topics.size(); ++topic) {
      out += TopicRecords(contents, ids, topic, &schemas_written);
    }
    for (const BagTestMessage& message : contents.messages) {
      const auto channel = static_cast<uint16_t>(TopicIndex(contents, message.topic) + 1);
      out += mcap::Message(channel, message.log_time_ns, Bytes(message.data));
    }
  }
  out += mcap::DataEnd();
  uint64_t summary_offsets_at = 0;
  if (options.summary) {
    layout.summary_start = out.size();
    std::set<uint16_t> schemas_written;
    std::string topic_records;
    for (size_t topic = 0; topic < contents.topics.size(); ++topic) {
      topic_records += TopicRecords(contents, ids, topic, &schemas_written);
    }
    out += topic_records;
    const uint64_t statistics_at = out.size();
    out += Statistics(contents, ids, layout.chunk_offsets.size());
    const uint64_t chunk_indexes_at = out.size();
    out += chunks.chunk_indexes;
    summary_offsets_at = out.size();
    out += SummaryOffset(0x04, layout.summary_start, topic_records.size());
    out += SummaryOffset(0x0B, statistics_at, chunk_indexes_at - statistics_at);
    if (!chunks.chunk_indexes.empty()) {
      out += SummaryOffset(0x08, chunk_indexes_at, chunks.chunk_indexes.size());
    }
  }
  // As the mcap library writes it: the CRC of the summary section and of the
  // footer up to the CRC field.
  uint32_t summary_crc = 0;
  if (options.summary) {
    const std::string footer = mcap::Footer(layout.summary_start, summary_offsets_at);
    summary_crc =
        mcap::Crc32(out.substr(layout.summary_start) + footer.substr(0, footer.size() - 4));
  }
  out += mcap::Footer(layout.summary_start, summary_offsets_at, summary_crc) + mcap::Magic();
  WriteBytes(file, out);
  return layout;
}

fs::path WriteRos2McapBag(const fs::path& folder, const BagTestContents& contents,
                          const McapWriteOptions& options) {
  fs::create_directories(folder);
  const std::string file_name = folder.filename().string() + "_0.mcap";
  WriteMcap(folder / file_name, contents, options);
  WriteBytes(folder / "metadata.yaml", MetadataYaml(contents, "mcap", file_name));
  return folder / file_name;
}

namespace mcap {

std::string Magic() { return std::string("\x89MCAP0\r\n", 8); }

namespace {
std::string LittleEndian(uint64_t value, int bytes) {
  std::string out;
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
  return out;
}
}  // namespace

std::string U16(uint16_t value) { return LittleEndian(value, 2); }
std::string U32(uint32_t value) { return LittleEndian(value, 4); }
std::string U64(uint64_t value) { return LittleEndian(value, 8); }
std::string Str(const std::string& text) { return U32(static_cast<uint32_t>(text.size())) + text; }

std::string Record(uint8_t opcode, const std::string& body) {
  return std::string(1, static_cast<char>(opcode)) + U64(body.size()) + body;
}

std::string Header() { return Record(0x01, Str("ros2") + Str("boicp tests")); }

std::string Schema(uint16_t id, const std::string& name) {
  return Record(0x03, U16(id) + Str(name) + Str("ros2msg") + Str("# definition\n"));
}

std::string Channel(uint16_t id, uint16_t schema_id, const std::string& topic,
                    const std::string& encoding) {
  const std::string metadata = Str("offered_qos_profiles") + Str("");
  return Record(0x04, U16(id) + U16(schema_id) + Str(topic) + Str(encoding) +
                          U32(static_cast<uint32_t>(metadata.size())) + metadata);
}

std::string Message(uint16_t channel, int64_t log_time_ns, const std::string& data) {
  const auto t = static_cast<uint64_t>(log_time_ns);
  return Record(0x05, U16(channel) + U32(0) + U64(t) + U64(t) + data);
}

std::string Chunk(const std::string& compression, const std::string& records,
                  uint64_t uncompressed_size, uint32_t uncompressed_crc) {
  return Record(0x06, U64(0) + U64(0) + U64(uncompressed_size) + U32(uncompressed_crc) +
                          Str(compression) + U64(records.size()) + records);
}

uint32_t Crc32(const std::string& bytes) {
  return static_cast<uint32_t>(
      crc32_z(0, reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
}

std::string DataEnd() { return Record(0x0F, U32(0)); }

std::string Footer(uint64_t summary_start, uint64_t summary_offset_start, uint32_t summary_crc) {
  return Record(0x02, U64(summary_start) + U64(summary_offset_start) + U32(summary_crc));
}

std::string Zstd(const std::string& bytes) {
  std::string out(ZSTD_compressBound(bytes.size()), '\0');
  const size_t size = ZSTD_compress(out.data(), out.size(), bytes.data(), bytes.size(), 3);
  if (ZSTD_isError(size)) throw std::runtime_error("test bag: zstd failed");
  out.resize(size);
  return out;
}

std::string Lz4Frame(const std::string& bytes) {
  std::string out(LZ4F_compressFrameBound(bytes.size(), nullptr), '\0');
  const size_t size =
      LZ4F_compressFrame(out.data(), out.size(), bytes.data(), bytes.size(), nullptr);
  if (LZ4F_isError(size)) throw std::runtime_error("test bag: lz4 failed");
  out.resize(size);
  return out;
}

}  // namespace mcap
}  // namespace boicp::test
