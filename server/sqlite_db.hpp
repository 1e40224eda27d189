#pragma once
// A thin RAII layer over the SQLite C API: one connection, prepared
// statements, transactions. Every failure throws std::runtime_error with
// SQLite's message. Not thread-safe; JobStore serialises access.

#include <cstdint>
#include <string>

struct sqlite3;
struct sqlite3_stmt;

namespace boicp::server {

class SqliteStatement {
 public:
  SqliteStatement(sqlite3* db, const std::string& sql);
  ~SqliteStatement();
  SqliteStatement(const SqliteStatement&) = delete;
  SqliteStatement& operator=(const SqliteStatement&) = delete;

  // Parameters are 1-based, as in SQLite.
  SqliteStatement& Bind(int index, int64_t value);
  SqliteStatement& Bind(int index, double value);
  SqliteStatement& Bind(int index, const std::string& text);
  SqliteStatement& BindBlob(int index, const std::string& bytes);

  /// Runs one step; true while a row is available.
  bool Step();
  /// Steps to completion, for statements that return no rows.
  void Run();
  /// Makes the statement ready to bind and run again.
  void Reset();

  // Columns are 0-based, as in SQLite.
  int64_t ColumnInt(int column) const;
  std::string ColumnText(int column) const;
  std::string ColumnBlob(int column) const;

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

class SqliteDatabase {
 public:
  /// Opens (creating if needed) the database file.
  explicit SqliteDatabase(const std::string& path);
  ~SqliteDatabase();
  SqliteDatabase(const SqliteDatabase&) = delete;
  SqliteDatabase& operator=(const SqliteDatabase&) = delete;

  /// Runs one or more statements that return nothing.
  void Exec(const std::string& sql);
  SqliteStatement Prepare(const std::string& sql) { return SqliteStatement(db_, sql); }

  /// BEGIN IMMEDIATE ... COMMIT; rolls back when destroyed uncommitted.
  class Transaction {
   public:
    explicit Transaction(SqliteDatabase& db);
    ~Transaction();
    Transaction(const Transaction&) = delete;
    Transaction& operator=(const Transaction&) = delete;
    void Commit();

   private:
    SqliteDatabase& db_;
    bool done_ = false;
  };

 private:
  sqlite3* db_ = nullptr;
};

}  // namespace boicp::server
