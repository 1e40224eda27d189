#pragma once
// The job store's SQLite access on SQLiteCpp (libsqlitecpp-dev): opening the
// connection, binding a statement's parameters in one call, and telling a
// failing disk from a failing statement.

#include <string>

#include <SQLiteCpp/Database.h>
#include <SQLiteCpp/Exception.h>
#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>

namespace boicp::server {

/// Bytes bound as a BLOB (a std::string binds as TEXT, and SQLite never
/// finds a TEXT value equal to a BLOB one).
struct Blob {
  std::string bytes;
};

/// Opens (creating if needed) the database at `path`, for use from several
/// threads one at a time, waiting up to 5 s for another connection's lock.
/// Throws as RethrowSqliteError does.
SQLite::Database OpenDatabase(const std::string& path);

/// Binds `value` to parameter `index` (1-based): integers, doubles and
/// strings as SQLiteCpp binds them, a Blob as a BLOB.
template <typename Value>
void BindArgument(SQLite::Statement& statement, int index, const Value& value) {
  statement.bind(index, value);
}
void BindArgument(SQLite::Statement& statement, int index, const Blob& blob);

/// `sql` prepared with `args` bound to ?1, ?2, ... in order.
template <typename... Args>
SQLite::Statement Query(SQLite::Database& db, const std::string& sql, const Args&... args) {
  SQLite::Statement statement(db, sql);
  int index = 0;
  (BindArgument(statement, ++index, args), ...);
  return statement;
}

/// Runs `sql`, a statement that returns no rows, with `args` bound.
template <typename... Args>
void Run(SQLite::Database& db, const std::string& sql, const Args&... args) {
  Query(db, sql, args...).exec();
}

/// Throws `e` again as a StorageError when the disk, not the statement, is
/// the problem (full, read-only, I/O error, cannot open, no permission),
/// else as std::runtime_error; both name SQLite's message.
[[noreturn]] void RethrowSqliteError(const SQLite::Exception& e);

}  // namespace boicp::server
