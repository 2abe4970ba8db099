#pragma once
// Thin RAII wrappers over the SQLite C API for the rosbag2 sqlite3 reader and writer. Errors throw
// coloc::Error naming the database file, what was being done and SQLite's message.
#include <sqlite3.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

namespace coloc::io::detail {

class SqliteStatement {
 public:
  SqliteStatement(sqlite3* db, const std::string& sql, const std::string& path);
  ~SqliteStatement();
  SqliteStatement(SqliteStatement&& other) noexcept;
  SqliteStatement(const SqliteStatement&) = delete;
  SqliteStatement& operator=(const SqliteStatement&) = delete;

  SqliteStatement& bind(int index, std::int64_t value);
  SqliteStatement& bind(int index, const std::string& text);
  SqliteStatement& bindBlob(int index, const void* data, std::size_t size);
  /// True while rows come; false when done.
  bool step();
  /// Runs a statement that returns no rows, then resets it for reuse.
  void execute();
  void reset();

  std::int64_t columnInt64(int column) const;
  std::string columnText(int column) const;
  std::pair<const std::uint8_t*, std::size_t> columnBlob(int column) const;
  bool columnIsNull(int column) const;

 private:
  [[noreturn]] void fail(const std::string& what) const;

  sqlite3* db_;
  sqlite3_stmt* statement_ = nullptr;
  const std::string& path_;
  std::string sql_;
};

class SqliteDatabase {
 public:
  /// `uri` is passed to sqlite3_open_v2 with `flags`; `path` names the file in errors.
  SqliteDatabase(const std::string& uri, int flags, std::string path);
  ~SqliteDatabase();
  SqliteDatabase(const SqliteDatabase&) = delete;
  SqliteDatabase& operator=(const SqliteDatabase&) = delete;

  void execute(const std::string& sql);
  SqliteStatement prepare(const std::string& sql) const { return SqliteStatement(db_, sql, path_); }
  bool tableExists(const std::string& table) const;
  bool columnExists(const std::string& table, const std::string& column) const;
  std::int64_t lastInsertRowId() const { return sqlite3_last_insert_rowid(db_); }
  void close();

  const std::string& path() const { return path_; }

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

/// "file:<path>" with the characters SQLite's URI parser treats specially percent-encoded.
std::string sqliteFileUri(const std::string& path);

}  // namespace coloc::io::detail
