#pragma once
// Writers of small ROS 2 bags for tests and fuzz seeds: rosbag2 sqlite3 bag
// folders (.db3) and MCAP files, chunked or not, compressed or not, with or
// without a summary section. Messages are raw bytes; nothing here knows CDR.
// The MCAP building blocks are public too, so tests can assemble malformed
// files record by record.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace boicp::test {

struct BagTestTopic {
  std::string name;            // "/points"
  std::string type;            // "sensor_msgs/msg/PointCloud2"
  std::string format = "cdr";  // serialization_format (.db3) or message_encoding (.mcap)
};

struct BagTestMessage {
  std::string topic;  // one of the contents' topics
  int64_t log_time_ns = 0;
  std::vector<uint8_t> data;
};

/// What a bag holds: topics (in the order they get ids) and messages (in the
/// order they are written, whatever their log times).
struct BagTestContents {
  std::vector<BagTestTopic> topics;
  std::vector<BagTestMessage> messages;
};

/// Writes a rosbag2 sqlite3 bag folder: `folder`/metadata.yaml (storage_identifier
/// sqlite3) and `folder`/NAME_0.db3 (NAME being the folder's name) with rosbag2's
/// tables. Returns the .db3 path. A small `page_size` keeps fuzz seeds small.
std::filesystem::path WriteRos2SqliteBag(const std::filesystem::path& folder,
                                         const BagTestContents& contents, int page_size = 4096);

/// Switches a .db3 to WAL journal mode, as rosbag2's "resilient" preset records.
void SetWalMode(const std::filesystem::path& db3);

enum class McapCompression { kNone, kZstd, kLz4 };

struct McapWriteOptions {
  McapCompression compression = McapCompression::kNone;
  bool chunked = true;  // messages in chunks (with message indexes after each)
  bool summary = true;  // schemas, channels, statistics and chunk indexes after the data
  size_t messages_per_chunk = 2;
};

/// Where WriteMcap put things, for tests that damage a file on purpose.
struct McapLayout {
  std::vector<uint64_t> chunk_offsets;  // of each chunk record's opcode byte
  uint64_t summary_start = 0;           // 0 without a summary
};

/// Writes an MCAP file ("ros2" profile): one schema per type, one channel per topic.
McapLayout WriteMcap(const std::filesystem::path& file, const BagTestContents& contents,
                     const McapWriteOptions& options = {});

/// Writes a ROS 2 bag folder with MCAP storage: `folder`/metadata.yaml
/// (storage_identifier mcap) and `folder`/NAME_0.mcap. Returns the .mcap path.
std::filesystem::path WriteRos2McapBag(const std::filesystem::path& folder,
                                       const BagTestContents& contents,
                                       const McapWriteOptions& options = {});

/// Writes `bytes` to `file`, replacing it.
void WriteBytes(const std::filesystem::path& file, const std::string& bytes);

/// Reads `file` whole.
std::string ReadBytes(const std::filesystem::path& file);

/// MCAP building blocks: each returns the little-endian bytes of one field or record.
namespace mcap {
std::string Magic();
std::string U16(uint16_t value);
std::string U32(uint32_t value);
std::string U64(uint64_t value);
std::string Str(const std::string& text);  // u32 length, then the bytes
std::string Record(uint8_t opcode, const std::string& body);
std::string Header();
std::string Schema(uint16_t id, const std::string& name);
std::string Channel(uint16_t id, uint16_t schema_id, const std::string& topic,
                    const std::string& encoding = "cdr");
std::string Message(uint16_t channel, int64_t log_time_ns, const std::string& data);
/// A chunk of `records` as given (already compressed when `compression` is
/// not empty), declaring `uncompressed_size` and `uncompressed_crc` (the
/// CRC-32 of the uncompressed records; 0 = none).
std::string Chunk(const std::string& compression, const std::string& records,
                  uint64_t uncompressed_size, uint32_t uncompressed_crc = 0);
/// The CRC-32 MCAP stores for `bytes`.
uint32_t Crc32(const std::string& bytes);
std::string DataEnd();
/// `summary_crc` 0 = none (what a writer stores when it computed no CRC).
std::string Footer(uint64_t summary_start = 0, uint64_t summary_offset_start = 0,
                   uint32_t summary_crc = 0);
std::string Zstd(const std::string& bytes);
std::string Lz4Frame(const std::string& bytes);
}  // namespace mcap

}  // namespace boicp::test
