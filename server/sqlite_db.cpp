#include "sqlite_db.hpp"

#include <sqlite3.h>

#include <stdexcept>

#include "storage_errors.hpp"

namespace boicp::server {

SQLite::Database OpenDatabase(const std::string& path) {
  try {
    return SQLite::Database(path,
                            SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE | SQLite::OPEN_FULLMUTEX,
                            /*busy_timeout_ms=*/5000);
  } catch (const SQLite::Exception& e) {
    RethrowSqliteError(e);
  }
}

void BindArgument(SQLite::Statement& statement, int index, const Blob& blob) {
  statement.bind(index, blob.bytes.data(), static_cast<int>(blob.bytes.size()));
}

void RethrowSqliteError(const SQLite::Exception& e) {
  const std::string message = std::string("sqlite: ") + e.what();
  switch (e.getErrorCode() & 0xff) {
    case SQLITE_FULL:
    case SQLITE_READONLY:
    case SQLITE_IOERR:
    case SQLITE_CANTOPEN:
    case SQLITE_PERM:
      throw StorageError(message);
    default:
      throw std::runtime_error(message);
  }
}

}  // namespace boicp::server
