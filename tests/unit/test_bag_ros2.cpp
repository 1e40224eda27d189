// ROS 2 bags: .db3 folders and .mcap files written by the test
// writers read back the same through OpenBag, whatever the chunking,
// compression and summary; malformed files are refused with an InputError
// that names the file.

#include <cstdint>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/files_and_processes.hpp"
#include "../support/input_error.hpp"
#include "../support/ros2_bag_writer.hpp"
#include "boicp/io/bag_reader.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;
using test::BagTestContents;
using test::InputErrorMessage;
using test::McapCompression;
using test::McapWriteOptions;
using ::testing::HasSubstr;

const std::string kCdrHeader("\x00\x01\x00\x00", 4);  // little-endian CDR

std::vector<uint8_t> Payload(int seed, size_t size) {
  std::vector<uint8_t> bytes = {0x00, 0x01, 0x00, 0x00};  // CDR little-endian header
  for (size_t i = 0; i < size; ++i) bytes.push_back(static_cast<uint8_t>(seed * 31 + i));
  return bytes;
}

// Topics listed out of name order, log times out of file order, a tie on
// /points (file order must survive), a topic with no messages, an empty payload.
BagTestContents DriveContents() {
  BagTestContents contents;
  contents.topics = {{"/points", "sensor_msgs/msg/PointCloud2"},
                     {"/imu", "sensor_msgs/msg/Imu"},
                     {"/empty", "std_msgs/msg/String"}};
  contents.messages = {{"/points", 300, Payload(1, 40)},  {"/imu", 100, Payload(2, 8)},
                       {"/points", 200, Payload(3, 200)}, {"/imu", 150, {}},
                       {"/points", 300, Payload(5, 3)},   {"/imu", 400, Payload(6, 1000)},
                       {"/points", 50, Payload(7, 12)}};
  return contents;
}

// The expected /points payloads, in log-time order with the tie in file order.
std::vector<std::vector<uint8_t>> ExpectedPoints() {
  return {Payload(7, 12), Payload(3, 200), Payload(1, 40), Payload(5, 3)};
}

void ExpectDriveContents(BagReader& bag) {
  EXPECT_EQ(bag.encoding(), MessageEncoding::kCdr);
  const std::vector<BagTopic> topics = bag.Topics();
  ASSERT_EQ(topics.size(), 3u);
  EXPECT_EQ(topics[0].name, "/empty");
  EXPECT_EQ(topics[0].type, "std_msgs/msg/String");
  EXPECT_EQ(topics[0].messages, 0u);
  EXPECT_EQ(topics[1].name, "/imu");
  EXPECT_EQ(topics[1].type, "sensor_msgs/msg/Imu");
  EXPECT_EQ(topics[1].messages, 3u);
  EXPECT_EQ(topics[2].name, "/points");
  EXPECT_EQ(topics[2].type, "sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(topics[2].messages, 4u);
  EXPECT_EQ(bag.TimeRange(), std::make_pair(int64_t{50}, int64_t{400}));

  const std::vector<BagMessageRef> points = bag.Messages("/points");
  ASSERT_EQ(points.size(), 4u);
  const std::vector<int64_t> times = {50, 200, 300, 300};
  const auto expected = ExpectedPoints();
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i].log_time_ns, times[i]);
    EXPECT_EQ(points[i].size, expected[i].size());
    EXPECT_EQ(bag.Read(points[i]), expected[i]) << "message " << i;
  }
  const std::vector<BagMessageRef> imu = bag.Messages("/imu");
  ASSERT_EQ(imu.size(), 3u);
  EXPECT_EQ(bag.Read(imu[0]), Payload(2, 8));
  EXPECT_TRUE(bag.Read(imu[1]).empty());
  EXPECT_EQ(bag.Read(imu[2]), Payload(6, 1000));
  // Reading out of order works too (chunks are re-read).
  EXPECT_EQ(bag.Read(points[3]), expected[3]);
  EXPECT_EQ(bag.Read(points[0]), expected[0]);
  EXPECT_TRUE(bag.Messages("/empty").empty());
  EXPECT_TRUE(bag.Messages("/no_such_topic").empty());
}

// Opens and reads everything a bag holds, as a caller would.
void ReadEverything(const std::string& path, const BagLimits& limits = {}) {
  std::unique_ptr<BagReader> bag = OpenBag(path, limits);
  bag->TimeRange();
  for (const BagTopic& topic : bag->Topics()) {
    for (const BagMessageRef& ref : bag->Messages(topic.name)) bag->Read(ref);
  }
}

// --- ROS 2 .db3 --------------------------------------------------------------

TEST(Ros2SqliteBag, FolderReadsBackWhatWasWritten) {
  test::ScratchDir dir("bag_ros2");
  const fs::path db3 = test::WriteRos2SqliteBag(dir.path() / "drive", DriveContents());
  EXPECT_EQ(db3.filename(), "drive_0.db3");
  EXPECT_TRUE(IsBagPath((dir.path() / "drive").string()));

  std::unique_ptr<BagReader> bag = OpenBag((dir.path() / "drive").string());
  EXPECT_EQ(bag->storage(), BagStorage::kRos2Sqlite);
  EXPECT_EQ(bag->path(), db3.string());
  ExpectDriveContents(*bag);
  ExpectDriveContents(*OpenBag(db3.string()));  // the .db3 file itself
}

// The drive's messages split over storage files as rosbag2 splits a bag by
// size: every file lists every topic, each holds a run of the messages.
std::vector<BagTestContents> SplitDrive(const std::vector<size_t>& ends) {
  const BagTestContents whole = DriveContents();
  std::vector<BagTestContents> parts;
  size_t begin = 0;
  for (size_t end : ends) {
    BagTestContents part;
    part.topics = whole.topics;
    part.messages.assign(whole.messages.begin() + begin, whole.messages.begin() + end);
    parts.push_back(part);
    begin = end;
  }
  return parts;
}

// Writes `parts` as one bag folder `folder` (NAME_0, NAME_1, ... storage
// files beside one metadata.yaml) with `write` (WriteRos2SqliteBag or
// WriteRos2McapBag); returns the storage files in order.
template <typename Write>
std::vector<fs::path> WriteSplitBag(const fs::path& folder,
                                    const std::vector<BagTestContents>& parts, Write write) {
  std::vector<fs::path> files;
  for (size_t i = 0; i < parts.size(); ++i) {
    const fs::path staging = folder.parent_path() / ("part" + std::to_string(i));
    const fs::path written = write(staging, parts[i]);
    fs::create_directories(folder);
    if (i == 0) fs::copy_file(staging / "metadata.yaml", folder / "metadata.yaml");
    files.push_back(folder / (folder.filename().string() + "_" + std::to_string(i) +
                              written.extension().string()));
    fs::rename(written, files.back());
    fs::remove_all(staging);
  }
  return files;
}

// A split bag reads as the whole one: counts added, messages merged by log
// time with ties in file order (the /points tie at 300 spans two files), and
// each read from its own file. Eleven files put NAME_10 after NAME_9.
TEST(Ros2SplitBag, ReadsAsOneBagWhateverTheStorage) {
  test::ScratchDir dir("bag_split");
  const auto sqlite = [](const fs::path& f, const BagTestContents& c) {
    return test::WriteRos2SqliteBag(f, c);
  };
  const auto mcap = [](const fs::path& f, const BagTestContents& c) {
    return test::WriteRos2McapBag(f, c);
  };
  for (const std::string storage : {"db3", "mcap"}) {
    const fs::path folder = dir.path() / storage / "drive";
    const auto parts = SplitDrive({4, 7});
    const auto files = storage == "db3" ? WriteSplitBag(folder, parts, sqlite)
                                        : WriteSplitBag(folder, parts, mcap);
    std::unique_ptr<BagReader> bag = OpenBag(folder.string());
    EXPECT_EQ(bag->path(), folder.string());
    ExpectDriveContents(*bag);
    const std::vector<BagMessageRef> points = bag->Messages("/points");
    ASSERT_EQ(points.size(), 4u);
    EXPECT_EQ(points[0].file, 1u);  // logged at 50, written last
    EXPECT_EQ(points[2].file, 0u);
    EXPECT_EQ(points[3].file, 1u);
  }
  // The two messages of the /points tie in files 2 and 10 of eleven: file 2's
  // comes first, as rosbag2 wrote it (a name sort would put drive_10 first).
  const BagTestContents whole = DriveContents();
  std::vector<BagTestContents> parts(11, BagTestContents{whole.topics, {}});
  for (size_t i : {1, 2, 3, 5, 6}) parts[0].messages.push_back(whole.messages[i]);
  parts[2].messages = {whole.messages[4]};
  parts[10].messages = {whole.messages[0]};
  const fs::path folder = dir.path() / "eleven" / "drive";
  WriteSplitBag(folder, parts, sqlite);
  std::unique_ptr<BagReader> bag = OpenBag(folder.string());
  const std::vector<BagMessageRef> points = bag->Messages("/points");
  ASSERT_EQ(points.size(), 4u);
  EXPECT_EQ(points[2].file, 2u);
  EXPECT_EQ(bag->Read(points[2]), Payload(5, 3));
  EXPECT_EQ(points[3].file, 10u);
  EXPECT_EQ(bag->Read(points[3]), Payload(1, 40));
}

TEST(Ros2SplitBag, RefusesATopicWhoseTypeChangesBetweenFiles) {
  test::ScratchDir dir("bag_split");
  std::vector<BagTestContents> parts = SplitDrive({4, 7});
  parts[1].topics[1].type = "sensor_msgs/msg/NavSatFix";
  const fs::path folder = dir.path() / "drive";
  WriteSplitBag(folder, parts, [](const fs::path& f, const BagTestContents& c) {
    return test::WriteRos2SqliteBag(f, c);
  });
  EXPECT_THAT(InputErrorMessage([&] { OpenBag(folder.string())->Topics(); }),
              HasSubstr("topic /imu holds sensor_msgs/msg/NavSatFix, but sensor_msgs/msg/Imu"));
}

// rosbag2's "resilient" preset records in WAL mode; reading such a bag must
// not leave -shm/-wal files beside it (nor need to create them).
TEST(Ros2SqliteBag, WalModeBagReadsWithoutSideFiles) {
  test::ScratchDir dir("bag_ros2");
  const fs::path db3 = test::WriteRos2SqliteBag(dir.path() / "wal drive%", DriveContents());
  test::SetWalMode(db3);
  ExpectDriveContents(*OpenBag(db3.string()));
  EXPECT_FALSE(fs::exists(db3.string() + "-shm"));
  EXPECT_FALSE(fs::exists(db3.string() + "-wal"));
}

TEST(Ros2SqliteBag, EmptyBagHasNoTimeRange) {
  test::ScratchDir dir("bag_ros2");
  BagTestContents contents;
  contents.topics = {{"/points", "sensor_msgs/msg/PointCloud2"}};
  const fs::path db3 = test::WriteRos2SqliteBag(dir.path() / "empty", contents);
  std::unique_ptr<BagReader> bag = OpenBag(db3.string());
  EXPECT_EQ(bag->TimeRange(), std::make_pair(int64_t{0}, int64_t{0}));
  ASSERT_EQ(bag->Topics().size(), 1u);
  EXPECT_EQ(bag->Topics()[0].messages, 0u);
  EXPECT_TRUE(bag->Messages("/points").empty());
}

TEST(Ros2SqliteBag, RefusesANonCdrTopicWhenItsMessagesAreListed) {
  test::ScratchDir dir("bag_ros2");
  BagTestContents contents = DriveContents();
  contents.topics[1].format = "json";
  const fs::path db3 = test::WriteRos2SqliteBag(dir.path() / "drive", contents);
  std::unique_ptr<BagReader> bag = OpenBag(db3.string());
  EXPECT_EQ(bag->Topics().size(), 3u);
  EXPECT_EQ(bag->Messages("/points").size(), 4u);
  const std::string message = InputErrorMessage([&] { bag->Messages("/imu"); });
  EXPECT_THAT(message, HasSubstr("drive_0.db3"));
  EXPECT_THAT(message, HasSubstr("/imu"));
  EXPECT_THAT(message, HasSubstr("json"));
}

TEST(Ros2SqliteBag, RefusesAMessageOverTheLimit) {
  test::ScratchDir dir("bag_ros2");
  const fs::path db3 = test::WriteRos2SqliteBag(dir.path() / "drive", DriveContents());
  BagLimits limits;
  limits.max_message_bytes = 100;
  std::unique_ptr<BagReader> bag = OpenBag(db3.string(), limits);
  const std::vector<BagMessageRef> imu = bag->Messages("/imu");
  EXPECT_EQ(bag->Read(imu[0]), Payload(2, 8));
  EXPECT_THAT(InputErrorMessage([&] { bag->Read(imu[2]); }), HasSubstr("over the limit"));
}

TEST(Ros2SqliteBag, RefusesFilesThatAreNotRosbag2Databases) {
  test::ScratchDir dir("bag_ros2");
  const fs::path text = dir.path() / "notes.db3";
  test::WriteBytes(text, "this is not a database, just some text that is long enough\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadEverything(text.string()); }), HasSubstr("notes.db3"));

  const fs::path empty = dir.path() / "empty.db3";
  test::WriteBytes(empty, "");
  EXPECT_THAT(InputErrorMessage([&] { ReadEverything(empty.string()); }), HasSubstr("empty.db3"));

  const fs::path missing = dir.path() / "missing.db3";
  EXPECT_THAT(InputErrorMessage([&] { OpenBag(missing.string()); }), HasSubstr("missing.db3"));
}

TEST(Ros2SqliteBag, RefusesTruncatedDatabases) {
  test::ScratchDir dir("bag_ros2");
  const fs::path db3 = test::WriteRos2SqliteBag(dir.path() / "drive", DriveContents(), 512);
  const std::string bytes = test::ReadBytes(db3);
  for (size_t cut : {size_t{10}, size_t{99}, size_t{600}, bytes.size() / 2}) {
    const fs::path cut_file = dir.path() / ("cut_" + std::to_string(cut) + ".db3");
    test::WriteBytes(cut_file, bytes.substr(0, cut));
    EXPECT_THAT(InputErrorMessage([&] { ReadEverything(cut_file.string()); }),
                HasSubstr(cut_file.filename().string()))
        << "cut at " << cut;
  }
}

// --- ROS 2 .mcap -------------------------------------------------------------

using McapCase = std::tuple<McapCompression, bool, bool>;  // compression, chunked, summary

class McapRoundTrip : public ::testing::TestWithParam<McapCase> {};

TEST_P(McapRoundTrip, ReadsBackWhatWasWritten) {
  test::ScratchDir dir("bag_mcap");
  McapWriteOptions options;
  std::tie(options.compression, options.chunked, options.summary) = GetParam();
  const fs::path file = dir.path() / "drive.mcap";
  test::WriteMcap(file, DriveContents(), options);
  std::unique_ptr<BagReader> bag = OpenBag(file.string());
  EXPECT_EQ(bag->storage(), BagStorage::kMcap);
  ExpectDriveContents(*bag);
}

TEST_P(McapRoundTrip, FolderWithMetadataOpens) {
  test::ScratchDir dir("bag_mcap");
  McapWriteOptions options;
  std::tie(options.compression, options.chunked, options.summary) = GetParam();
  const fs::path file = test::WriteRos2McapBag(dir.path() / "drive", DriveContents(), options);
  EXPECT_EQ(file.filename(), "drive_0.mcap");
  std::unique_ptr<BagReader> bag = OpenBag((dir.path() / "drive").string());
  EXPECT_EQ(bag->path(), file.string());
  ExpectDriveContents(*bag);
}

TEST_P(McapRoundTrip, EveryCutIsRefusedNamingTheFile) {
  test::ScratchDir dir("bag_mcap");
  McapWriteOptions options;
  std::tie(options.compression, options.chunked, options.summary) = GetParam();
  const fs::path file = dir.path() / "whole.mcap";
  test::WriteMcap(file, DriveContents(), options);
  const std::string bytes = test::ReadBytes(file);
  const fs::path cut_file = dir.path() / "cut.mcap";
  // A footer and end magic are required, so no cut leaves a readable file:
  // every cut through the frame and first records, then a sample of the rest.
  for (size_t cut = 0; cut < bytes.size(); cut += cut < 160 || cut + 48 > bytes.size() ? 1 : 7) {
    test::WriteBytes(cut_file, bytes.substr(0, cut));
    EXPECT_THAT(InputErrorMessage([&] { ReadEverything(cut_file.string()); }),
                HasSubstr("cut.mcap"))
        << "cut at " << cut << " of " << bytes.size();
  }
}

INSTANTIATE_TEST_SUITE_P(Layouts, McapRoundTrip,
                         ::testing::Combine(::testing::Values(McapCompression::kNone,
                                                              McapCompression::kZstd,
                                                              McapCompression::kLz4),
                                            ::testing::Bool(), ::testing::Bool()));

TEST(McapBag, EmptyBagHasNoTimeRange) {
  test::ScratchDir dir("bag_mcap");
  BagTestContents contents;
  contents.topics = {{"/points", "sensor_msgs/msg/PointCloud2"}};
  for (bool summary : {false, true}) {
    const fs::path file = dir.path() / "empty.mcap";
    McapWriteOptions options;
    options.summary = summary;
    test::WriteMcap(file, contents, options);
    std::unique_ptr<BagReader> bag = OpenBag(file.string());
    EXPECT_EQ(bag->TimeRange(), std::make_pair(int64_t{0}, int64_t{0}));
    ASSERT_EQ(bag->Topics().size(), 1u);
    EXPECT_TRUE(bag->Messages("/points").empty());
  }
}

// Messages on /a, /b and /a, a chunk each, written to `file` (with a summary
// or not) and then the /b chunk damaged: its records length, after the fixed
// fields and the empty compression name, made huge.
test::McapLayout WriteMcapWithADamagedChunk(const fs::path& file, bool summary) {
  BagTestContents contents;
  contents.topics = {{"/a", "std_msgs/msg/String"}, {"/b", "std_msgs/msg/String"}};
  contents.messages = {
      {"/a", 1, Payload(1, 5)}, {"/b", 2, Payload(2, 5)}, {"/a", 3, Payload(3, 5)}};
  McapWriteOptions options;
  options.messages_per_chunk = 1;
  options.summary = summary;
  const test::McapLayout layout = test::WriteMcap(file, contents, options);
  EXPECT_EQ(layout.chunk_offsets.size(), 3u);
  std::string bytes = test::ReadBytes(file);
  bytes.replace(layout.chunk_offsets.at(1) + 9 + 32, 8, test::mcap::U64(UINT64_MAX));
  test::WriteBytes(file, bytes);
  return layout;
}

// With a summary, a topic's messages come from the chunks its index lists:
// a damaged chunk holding only another topic is never read.
TEST(McapBag, SummaryIndexSkipsChunksOfOtherTopics) {
  test::ScratchDir dir("bag_mcap");
  for (bool summary : {true, false}) {
    const fs::path file = dir.path() / "skip.mcap";
    const test::McapLayout layout = WriteMcapWithADamagedChunk(file, summary);

    std::unique_ptr<BagReader> bag = OpenBag(file.string());
    if (summary) {
      const std::vector<BagMessageRef> a = bag->Messages("/a");
      ASSERT_EQ(a.size(), 2u);
      EXPECT_EQ(bag->Read(a[1]), Payload(3, 5));
    } else {
      EXPECT_THAT(InputErrorMessage([&] { bag->Messages("/a"); }), HasSubstr("skip.mcap"));
    }
    const std::string message = InputErrorMessage([&] { bag->Messages("/b"); });
    EXPECT_THAT(message, HasSubstr("skip.mcap"));
    EXPECT_THAT(message,
                HasSubstr("chunk record at byte " + std::to_string(layout.chunk_offsets[1])));
  }
}

// A summary that fails its CRC is not trusted even where it still parses
// (here the last byte of a summary offset record, which the reader skips):
// the file is scanned instead, so the damaged /b chunk stops /a too. With
// the CRC intact, /a is read through the index.
TEST(McapBag, SummaryFailingItsCrcFallsBackToTheScan) {
  test::ScratchDir dir("bag_mcap");
  for (bool damaged_summary : {false, true}) {
    const fs::path file = dir.path() / "crc.mcap";
    WriteMcapWithADamagedChunk(file, true);
    if (damaged_summary) {
      std::string bytes = test::ReadBytes(file);
      const size_t footer_at = bytes.size() - (9 + 20 + 8);
      bytes[footer_at - 1] = static_cast<char>(bytes[footer_at - 1] ^ 0x40);
      test::WriteBytes(file, bytes);
    }

    std::unique_ptr<BagReader> bag = OpenBag(file.string());
    if (damaged_summary) {
      EXPECT_THAT(InputErrorMessage([&] { bag->Messages("/a"); }), HasSubstr("crc.mcap"));
    } else {
      ASSERT_EQ(bag->Messages("/a").size(), 2u);
    }
  }
}

// A summary whose statistics count messages the chunk index does not reach
// (here: loose messages) is not trusted; the file is read whole instead.
TEST(McapBag, SummaryThatDoesNotAddUpFallsBackToTheScan) {
  test::ScratchDir dir("bag_mcap");
  namespace m = test::mcap;
  const std::string body = m::Schema(1, "std_msgs/msg/String") + m::Channel(1, 1, "/a") +
                           m::Message(1, 5, kCdrHeader + "xy");
  std::string statistics = m::U64(1) + m::U16(1) + m::U32(1) + m::U32(0) + m::U32(0) + m::U32(0) +
                           m::U64(5) + m::U64(5) + m::U32(10) + m::U16(1) + m::U64(1);
  std::string bytes = m::Magic() + m::Header() + body + m::DataEnd();
  const uint64_t summary_at = bytes.size();
  bytes +=
      m::Schema(1, "std_msgs/msg/String") + m::Channel(1, 1, "/a") + m::Record(0x0B, statistics);
  bytes += m::Footer(summary_at) + m::Magic();
  const fs::path file = dir.path() / "loose.mcap";
  test::WriteBytes(file, bytes);
  std::unique_ptr<BagReader> bag = OpenBag(file.string());
  const std::vector<BagMessageRef> a = bag->Messages("/a");
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(bag->Read(a[0]), std::vector<uint8_t>({0, 1, 0, 0, 'x', 'y'}));
}

// A small valid file's bytes up to the data end, for the malformed cases to extend.
std::string McapStart() {
  namespace m = test::mcap;
  return m::Magic() + m::Header() + m::Schema(1, "sensor_msgs/msg/PointCloud2") +
         m::Channel(1, 1, "/points");
}

std::string McapEnd() { return test::mcap::DataEnd() + test::mcap::Footer() + test::mcap::Magic(); }

class McapMalformed : public ::testing::Test {
 protected:
  // Writes `bytes` as NAME.mcap and returns the message reading it all throws.
  std::string Refusal(const std::string& name, const std::string& bytes,
                      const BagLimits& limits = {}) {
    const fs::path file = dir_.path() / (name + ".mcap");
    test::WriteBytes(file, bytes);
    const std::string message = InputErrorMessage([&] { ReadEverything(file.string(), limits); });
    EXPECT_THAT(message, HasSubstr(name + ".mcap"));
    return message;
  }

  test::ScratchDir dir_{"bag_mcap"};
};

TEST_F(McapMalformed, WrongMagic) {
  std::string bytes = McapStart() + McapEnd();
  bytes[1] = 'X';
  EXPECT_THAT(Refusal("wrong_magic", bytes), HasSubstr("not an MCAP file"));
  EXPECT_THAT(Refusal("rosbag1", "#ROSBAG V2.0\n" + bytes), HasSubstr("not an MCAP file"));
}

TEST_F(McapMalformed, MissingFile) {
  EXPECT_THAT(InputErrorMessage([&] { OpenBag((dir_.path() / "gone.mcap").string()); }),
              HasSubstr("gone.mcap"));
}

TEST_F(McapMalformed, ChunkDeclaringAHugeUncompressedSize) {
  namespace m = test::mcap;
  const std::string records = m::Message(1, 1, kCdrHeader);
  const std::string bytes =
      McapStart() + m::Chunk("zstd", m::Zstd(records), uint64_t{1} << 50) + McapEnd();
  EXPECT_THAT(Refusal("huge_chunk", bytes), HasSubstr("over the limit"));
  // And one that is honest but over a caller's limit.
  BagLimits limits;
  limits.max_message_bytes = 16;
  const std::string honest =
      McapStart() + m::Chunk("zstd", m::Zstd(records), records.size()) + McapEnd();
  EXPECT_THAT(Refusal("over_limit", honest, limits), HasSubstr("over the limit"));
}

TEST_F(McapMalformed, ChunkDecompressingToAnotherSize) {
  namespace m = test::mcap;
  const std::string records = m::Message(1, 1, std::string(100, 'x'));
  for (const std::string& compression : {std::string("zstd"), std::string("lz4")}) {
    const std::string compressed = compression == "zstd" ? m::Zstd(records) : m::Lz4Frame(records);
    Refusal("short_" + compression,
            McapStart() + m::Chunk(compression, compressed, 50) + McapEnd());
    Refusal("long_" + compression,
            McapStart() + m::Chunk(compression, compressed, records.size() + 50) + McapEnd());
    Refusal(
        "garbage_" + compression,
        McapStart() + m::Chunk(compression, std::string(40, '\x55'), records.size()) + McapEnd());
  }
}

// A chunk whose records do not match its CRC is refused, compressed or not;
// the round trips above read chunks whose CRCs match, and chunks with none.
TEST_F(McapMalformed, ChunkFailingItsCrc) {
  namespace m = test::mcap;
  const std::string records = m::Message(1, 1, kCdrHeader + std::string(64, '\x2a'));
  const uint32_t wrong = m::Crc32(records) ^ 0x10u;
  EXPECT_THAT(
      Refusal("crc_plain", McapStart() + m::Chunk("", records, records.size(), wrong) + McapEnd()),
      HasSubstr("fails its CRC check"));
  EXPECT_THAT(
      Refusal("crc_zstd",
              McapStart() + m::Chunk("zstd", m::Zstd(records), records.size(), wrong) + McapEnd()),
      HasSubstr("the bag is corrupt"));
  EXPECT_THAT(Refusal("crc_lz4", McapStart() +
                                     m::Chunk("lz4", m::Lz4Frame(records), records.size(), wrong) +
                                     McapEnd()),
              HasSubstr("fails its CRC check"));
  // A byte of a point changed inside a written bag's uncompressed chunk.
  McapWriteOptions options;
  options.compression = McapCompression::kNone;
  const fs::path whole = dir_.path() / "whole.mcap";
  test::WriteMcap(whole, DriveContents(), options);
  std::string bytes = test::ReadBytes(whole);
  const std::vector<uint8_t> imu = Payload(6, 1000);
  const size_t payload = bytes.find(std::string(imu.begin(), imu.end()));
  ASSERT_NE(payload, std::string::npos);
  bytes[payload + 100] ^= 0x01;
  EXPECT_THAT(Refusal("flipped", bytes), HasSubstr("fails its CRC check"));
}

TEST_F(McapMalformed, RecordLengthPastTheEnd) {
  namespace m = test::mcap;
  const std::string message = m::Message(1, 1, kCdrHeader);
  std::string bytes = McapStart() + message + McapEnd();
  bytes.replace(McapStart().size() + 1, 8, m::U64(1000));
  EXPECT_THAT(Refusal("long_record", bytes), HasSubstr("past the end"));
  // The same inside an uncompressed chunk.
  std::string records = message;
  records.replace(1, 8, m::U64(1000));
  EXPECT_THAT(
      Refusal("long_in_chunk", McapStart() + m::Chunk("", records, records.size()) + McapEnd()),
      HasSubstr("past the end"));
}

TEST_F(McapMalformed, UnknownCompression) {
  namespace m = test::mcap;
  const std::string records = m::Message(1, 1, kCdrHeader);
  EXPECT_THAT(
      Refusal("brotli", McapStart() + m::Chunk("brotli", records, records.size()) + McapEnd()),
      HasSubstr("brotli"));
}

TEST_F(McapMalformed, NonCdrEncoding) {
  namespace m = test::mcap;
  const std::string bytes = m::Magic() + m::Header() + m::Schema(1, "foo") +
                            m::Channel(1, 1, "/json", "json") + m::Message(1, 1, "{}") + McapEnd();
  const std::string message = Refusal("json", bytes);
  EXPECT_THAT(message, HasSubstr("/json"));
  EXPECT_THAT(message, HasSubstr("'json'"));
}

TEST_F(McapMalformed, MessageOnAnUndefinedChannel) {
  EXPECT_THAT(Refusal("no_channel", McapStart() + test::mcap::Message(7, 1, "abcd") + McapEnd()),
              HasSubstr("channel 7"));
}

TEST_F(McapMalformed, ChannelWithAnUndefinedSchema) {
  namespace m = test::mcap;
  const std::string bytes = m::Magic() + m::Header() + m::Channel(1, 9, "/points") + McapEnd();
  EXPECT_THAT(Refusal("no_schema", bytes), HasSubstr("schema 9"));
}

TEST_F(McapMalformed, NoFooter) {
  const std::string message = Refusal("no_footer", McapStart() + test::mcap::DataEnd());
  EXPECT_THAT(message, HasSubstr("without a footer"));
}

TEST_F(McapMalformed, FirstRecordIsNotAHeader) {
  EXPECT_THAT(Refusal("no_header", test::mcap::Magic() + test::mcap::DataEnd() + McapEnd()),
              HasSubstr("not a header"));
}

}  // namespace
}  // namespace boicp
