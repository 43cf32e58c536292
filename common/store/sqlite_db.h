// A small SQLite wrapper for the stateful services (codebook, index,
// coordinator): one database file per service under its --data_dir, WAL mode,
// prepared statements with typed binds, absl::Status errors.
//
// Durability: WAL with synchronous=NORMAL. A committed transaction survives a
// kill -9 of the process (the WAL is in the OS's page cache); only a power
// loss or kernel crash may lose the last transactions. That is the failure the
// services promise to survive ("an acknowledged add survives kill -9").
//
// Space: a file created by this wrapper is in incremental auto_vacuum mode, so
// `PRAGMA incremental_vacuum` gives freed pages back to the file system (the
// coordinator does after freeing stored features); otherwise SQLite keeps
// them for reuse and the file never shrinks.
//
// Not part of the algorithm core (common/ modules before pipeline never use
// it). A Database is used by one thread at a time; services guard it with
// their own mutex.
#ifndef MESHSEEK_COMMON_STORE_SQLITE_DB_H_
#define MESHSEEK_COMMON_STORE_SQLITE_DB_H_

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

struct sqlite3;
struct sqlite3_stmt;

namespace meshseek {

class Statement;
class Transaction;

class Database {
 public:
  /// Opens (creating if needed) the database file at `path`, in WAL mode with
  /// foreign keys on. Internal error naming the path when it cannot.
  static absl::StatusOr<std::unique_ptr<Database>> Open(const std::string& path);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  /// Runs one or more statements without results (schema, BEGIN, COMMIT).
  absl::Status Execute(absl::string_view sql);
  /// Prepares one statement.
  absl::StatusOr<Statement> Prepare(absl::string_view sql);
  /// Rows changed by the last INSERT, UPDATE or DELETE.
  int64_t Changes() const;
  /// PRAGMA user_version: the schema version a service stores (0 in a new
  /// database).
  absl::StatusOr<int64_t> UserVersion();
  absl::Status SetUserVersion(int64_t version);
  const std::string& path() const { return path_; }

 private:
  Database(sqlite3* db, std::string path) : db_(db), path_(std::move(path)) {}
  absl::Status Error(absl::string_view what) const;
  friend class Statement;

  sqlite3* db_;
  std::string path_;
};

// A prepared statement: bind (1-based, as SQLite), Step through rows, read
// columns (0-based). Reset() to run it again.
class Statement {
 public:
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&&) = delete;
  ~Statement();

  Statement& Bind(int index, int64_t value);
  Statement& Bind(int index, double value);
  Statement& Bind(int index, absl::string_view text);
  Statement& BindBlob(int index, absl::string_view bytes);

  /// true while there is a row to read, false when done; an error otherwise
  /// (also for a bind that failed).
  absl::StatusOr<bool> Step();
  /// Runs a statement that returns no rows.
  absl::Status Run();
  void Reset();

  int64_t ColumnInt(int column) const;
  double ColumnDouble(int column) const;
  std::string ColumnText(int column) const;
  std::string ColumnBlob(int column) const;
  bool ColumnIsNull(int column) const;

 private:
  friend class Database;
  Statement(Database* db, sqlite3_stmt* stmt) : db_(db), stmt_(stmt) {}
  void NoteBind(int rc);

  Database* db_;
  sqlite3_stmt* stmt_;
  int bind_error_ = 0;
};

// Statements that belong together: BEGIN IMMEDIATE on Begin, COMMIT on
// Commit, ROLLBACK when destroyed uncommitted (an early error return undoes
// everything since Begin). Not nestable; the Database's guard must be held
// for the transaction's whole life.
class Transaction {
 public:
  static absl::StatusOr<Transaction> Begin(Database* db);
  Transaction(Transaction&& other) noexcept : db_(other.db_) { other.db_ = nullptr; }
  Transaction& operator=(Transaction&&) = delete;
  ~Transaction();

  absl::Status Commit();

 private:
  explicit Transaction(Database* db) : db_(db) {}
  Database* db_;  // null once committed or rolled back
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_STORE_SQLITE_DB_H_
