// ROS 2 bags stored by rosbag2's sqlite3 plugin (.db3): a `topics` table and
// a `messages` table whose `data` column holds each message's CDR bytes. The
// file is opened read-only and every SQLite failure becomes an InputError.

#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bag_readers.hpp"
#include "boicp/util/types.hpp"

namespace boicp::io_detail {
// Named, so that a unity batch holding another bag reader sees no clash.
namespace sqlite_bag {
namespace {

struct DatabaseCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using Database = std::unique_ptr<sqlite3, DatabaseCloser>;

struct StatementFinalizer {
  void operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }
};
using Statement = std::unique_ptr<sqlite3_stmt, StatementFinalizer>;

// One row of the topics table.
struct SqliteTopic {
  int64_t id = 0;
  std::string name;
  std::string type;
  std::string format;  // serialization_format: "cdr" for every bag boicp reads
};

// A column's bytes as a size, whether SQLite stores it as a blob or as text
// (length() of text counts characters, not bytes); length() of a blob is
// answered without loading the blob.
constexpr const char* kDataBytes =
    "CASE typeof(data) WHEN 'blob' THEN length(data) ELSE length(CAST(data AS BLOB)) END";

std::string ColumnText(sqlite3_stmt* statement, int column) {
  const unsigned char* text = sqlite3_column_text(statement, column);
  if (text == nullptr) return "";
  return {reinterpret_cast<const char*>(text),
          static_cast<size_t>(sqlite3_column_bytes(statement, column))};
}

// The URI to open `path` with. A finished bag is opened immutable: SQLite then
// takes no locks and creates no -shm/-wal files beside it, which also lets a
// WAL-mode bag (rosbag2's "resilient" preset) be read from read-only media.
// A bag with a -wal file beside it still holds messages there, so it is
// opened normally, read-only.
std::string OpenUri(const std::string& path) {
  std::string uri = "file:";
  for (const unsigned char c : path) {
    if (std::isalnum(c) || std::strchr("/-._~", c) != nullptr) {
      uri += static_cast<char>(c);
    } else {
      static const char kHex[] = "0123456789ABCDEF";
      uri += {'%', kHex[c >> 4], kHex[c & 15]};
    }
  }
  std::error_code error;
  if (!std::filesystem::exists(path + "-wal", error)) uri += "?immutable=1";
  return uri;
}

class Ros2SqliteBag final : public BagReader {
 public:
  Ros2SqliteBag(std::string path, const BagLimits& limits)
      : path_(std::move(path)), limits_(limits) {
    OpenReadOnly();
    RequireRosbagTables();
    LoadTopics();
    list_statement_ = Prepare(std::string("SELECT rowid, timestamp, ") + kDataBytes +
                              " FROM messages WHERE topic_id = ? ORDER BY timestamp, rowid");
    size_statement_ =
        Prepare(std::string("SELECT topic_id, ") + kDataBytes + " FROM messages WHERE rowid = ?");
    data_statement_ = Prepare("SELECT data FROM messages WHERE rowid = ?");
  }

  const std::string& path() const override { return path_; }
  BagStorage storage() const override { return BagStorage::kRos2Sqlite; }
  MessageEncoding encoding() const override { return MessageEncoding::kCdr; }

  std::vector<BagTopic> Topics() override {
    Statement count = Prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id");
    std::vector<BagTopic> result;
    for (const SqliteTopic& topic : topics_) result.push_back({topic.name, topic.type, 0});
    while (Step(count.get(), "counting messages")) {
      const SqliteTopic* topic = TopicById(sqlite3_column_int64(count.get(), 0));
      if (topic == nullptr) continue;  // rows of a topic the table does not list
      result[static_cast<size_t>(topic - topics_.data())].messages =
          static_cast<uint64_t>(sqlite3_column_int64(count.get(), 1));
    }
    return result;
  }

  std::pair<int64_t, int64_t> TimeRange() override {
    Statement range = Prepare(
        "SELECT MIN(timestamp), MAX(timestamp), COUNT(*) FROM messages "
        "WHERE topic_id IN (SELECT id FROM topics)");
    if (!Step(range.get(), "reading the time range") || sqlite3_column_int64(range.get(), 2) == 0) {
      return {0, 0};
    }
    return {sqlite3_column_int64(range.get(), 0), sqlite3_column_int64(range.get(), 1)};
  }

  std::vector<BagMessageRef> Messages(const std::string& topic_name) override {
    const SqliteTopic* topic = TopicByName(topic_name);
    if (topic == nullptr) return {};
    RequireCdr(*topic);
    sqlite3_stmt* list = Reset(list_statement_.get());
    sqlite3_bind_int64(list, 1, topic->id);
    std::vector<BagMessageRef> result;
    while (Step(list, "listing messages")) {
      BagMessageRef ref;
      ref.position = static_cast<uint64_t>(sqlite3_column_int64(list, 0));
      ref.log_time_ns = sqlite3_column_int64(list, 1);
      ref.size = static_cast<uint64_t>(sqlite3_column_int64(list, 2));
      result.push_back(ref);
    }
    return result;
  }

  std::vector<uint8_t> Read(const BagMessageRef& message) override {
    const auto id = static_cast<sqlite3_int64>(message.position);
    RequireReadable(id);
    sqlite3_stmt* data = Reset(data_statement_.get());
    sqlite3_bind_int64(data, 1, id);
    if (!Step(data, "reading a message")) Fail("no message with id " + std::to_string(id));
    const auto* bytes = static_cast<const uint8_t*>(sqlite3_column_blob(data, 0));
    const auto size = static_cast<size_t>(sqlite3_column_bytes(data, 0));
    if (bytes == nullptr) return {};
    return {bytes, bytes + size};
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(path_ + ": " + problem);
  }

  [[noreturn]] void FailSqlite(const std::string& doing) const {
    Fail(doing + ": " + sqlite3_errmsg(db_.get()));
  }

  void OpenReadOnly() {
    sqlite3* raw = nullptr;
    const int status = sqlite3_open_v2(OpenUri(path_).c_str(), &raw,
                                       SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr);
    db_.reset(raw);  // sqlite3_open_v2 hands back a handle to close even when it fails
    if (status != SQLITE_OK) {
      Fail(std::string("cannot open as a SQLite database: ") +
           (raw != nullptr ? sqlite3_errmsg(raw) : sqlite3_errstr(status)));
    }
    // The schema comes from the file: refuse what a hostile one could smuggle in
    // (functions with side effects in views, writes to the schema).
    sqlite3_db_config(db_.get(), SQLITE_DBCONFIG_DEFENSIVE, 1, nullptr);
#ifdef SQLITE_DBCONFIG_TRUSTED_SCHEMA
    sqlite3_db_config(db_.get(), SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, nullptr);
#endif
  }

  // Both tables must be real tables: a view of the same name could compute
  // rows forever (a recursive CTE).
  void RequireRosbagTables() {
    Statement tables = PrepareOrRefuse(
        "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND name IN ('topics', "
        "'messages')");
    if (!Step(tables.get(), "reading the schema") || sqlite3_column_int64(tables.get(), 0) != 2) {
      Fail("not a ROS 2 bag: the database lacks rosbag2's topics and messages tables");
    }
    // Messages are located by rowid (rosbag2's `id INTEGER PRIMARY KEY` is
    // it), which a declared column of that name would hide.
    Statement shadowed = PrepareOrRefuse(
        "SELECT COUNT(*) FROM pragma_table_info('messages') WHERE lower(name) = 'rowid'");
    if (!Step(shadowed.get(), "reading the schema") ||
        sqlite3_column_int64(shadowed.get(), 0) != 0) {
      Fail("not a ROS 2 bag: its messages table declares a column named rowid");
    }
  }

  void LoadTopics() {
    Statement select = PrepareOrRefuse(
        "SELECT id, name, type, serialization_format FROM topics ORDER BY name, id");
    PrepareOrRefuse("SELECT rowid, topic_id, timestamp, data FROM messages LIMIT 0");
    while (Step(select.get(), "reading the topics table")) {
      SqliteTopic topic;
      topic.id = sqlite3_column_int64(select.get(), 0);
      topic.name = ColumnText(select.get(), 1);
      topic.type = ColumnText(select.get(), 2);
      topic.format = ColumnText(select.get(), 3);
      if (!topics_.empty() && topics_.back().name == topic.name) {
        Fail("topic " + topic.name + " is listed twice in the topics table");
      }
      if (TopicById(topic.id) != nullptr) {
        Fail("topics " + TopicById(topic.id)->name + " and " + topic.name + " share id " +
             std::to_string(topic.id));
      }
      topics_.push_back(std::move(topic));
    }
  }

  // Preparing against rosbag2's schema is where a file that is not a database,
  // or a database of another kind, shows itself.
  Statement PrepareOrRefuse(const std::string& sql) {
    sqlite3_stmt* raw = nullptr;
    if (sqlite3_prepare_v2(db_.get(), sql.c_str(), -1, &raw, nullptr) != SQLITE_OK) {
      sqlite3_finalize(raw);
      Fail(std::string("not a ROS 2 .db3 bag (") + sqlite3_errmsg(db_.get()) + ")");
    }
    return Statement(raw);
  }

  Statement Prepare(const std::string& sql) {
    sqlite3_stmt* raw = nullptr;
    if (sqlite3_prepare_v2(db_.get(), sql.c_str(), -1, &raw, nullptr) != SQLITE_OK) {
      sqlite3_finalize(raw);
      FailSqlite("querying the bag");
    }
    return Statement(raw);
  }

  static sqlite3_stmt* Reset(sqlite3_stmt* statement) {
    sqlite3_reset(statement);
    sqlite3_clear_bindings(statement);
    return statement;
  }

  // True for a row, false when done; a corrupt page or other failure throws.
  bool Step(sqlite3_stmt* statement, const std::string& doing) {
    const int status = sqlite3_step(statement);
    if (status == SQLITE_ROW) return true;
    if (status == SQLITE_DONE) return false;
    FailSqlite(doing);
  }

  const SqliteTopic* TopicById(int64_t id) const {
    for (const SqliteTopic& topic : topics_) {
      if (topic.id == id) return &topic;
    }
    return nullptr;
  }

  const SqliteTopic* TopicByName(const std::string& name) const {
    const auto it = std::lower_bound(
        topics_.begin(), topics_.end(), name,
        [](const SqliteTopic& topic, const std::string& key) { return topic.name < key; });
    return it != topics_.end() && it->name == name ? &*it : nullptr;
  }

  void RequireCdr(const SqliteTopic& topic) const {
    if (topic.format != "cdr") {
      Fail("topic " + topic.name + " is serialized as '" + topic.format +
           "'; boicp reads cdr messages only");
    }
  }

  // The message exists, belongs to a cdr topic, and is within the size limit:
  // checked before SQLite is asked for the bytes.
  void RequireReadable(sqlite3_int64 id) {
    sqlite3_stmt* size = Reset(size_statement_.get());
    sqlite3_bind_int64(size, 1, id);
    if (!Step(size, "reading a message")) Fail("no message with id " + std::to_string(id));
    const SqliteTopic* topic = TopicById(sqlite3_column_int64(size, 0));
    if (topic == nullptr) Fail("message " + std::to_string(id) + " belongs to no listed topic");
    RequireCdr(*topic);
    const auto bytes = static_cast<uint64_t>(sqlite3_column_int64(size, 1));
    if (bytes > limits_.max_message_bytes) {
      Fail("message " + std::to_string(id) + " on " + topic->name + " has " +
           std::to_string(bytes) + " bytes, over the limit of " +
           std::to_string(limits_.max_message_bytes));
    }
  }

  std::string path_;
  BagLimits limits_;
  Database db_;
  std::vector<SqliteTopic> topics_;  // sorted by name
  Statement list_statement_;
  Statement size_statement_;
  Statement data_statement_;
};

}  // namespace
}  // namespace sqlite_bag

std::unique_ptr<BagReader> OpenRos2SqliteBag(const std::string& path, const BagLimits& limits) {
  return std::make_unique<sqlite_bag::Ros2SqliteBag>(path, limits);
}

}  // namespace boicp::io_detail
