#include "common/store/sqlite_db.h"

#include <cstdio>
#include <filesystem>
#include <string>

#include "gtest/gtest.h"

namespace meshseek {
namespace {

std::string TempPath(const std::string& name) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::remove(path.c_str());
  std::remove((path + "-wal").c_str());
  std::remove((path + "-shm").c_str());
  return path;
}

TEST(DatabaseTest, StoresAndReadsBackTypedValuesAcrossReopen) {
  const std::string path = TempPath("sqlite_db_test_roundtrip.db");
  {
    auto db = Database::Open(path);
    ASSERT_TRUE(db.ok()) << db.status();
    ASSERT_TRUE((*db)->Execute("CREATE TABLE t (k TEXT PRIMARY KEY, n INTEGER, x REAL, b BLOB)").ok());
    auto insert = (*db)->Prepare("INSERT INTO t VALUES (?, ?, ?, ?)");
    ASSERT_TRUE(insert.ok()) << insert.status();
    const std::string blob("a\0b", 3);
    ASSERT_TRUE(insert->Bind(1, "key").Bind(2, int64_t{1} << 40).Bind(3, 0.25).BindBlob(4, blob).Run().ok());
    EXPECT_EQ((*db)->Changes(), 1);
  }
  auto db = Database::Open(path);
  ASSERT_TRUE(db.ok());
  auto select = (*db)->Prepare("SELECT k, n, x, b FROM t");
  ASSERT_TRUE(select.ok());
  auto row = select->Step();
  ASSERT_TRUE(row.ok() && *row);
  EXPECT_EQ(select->ColumnText(0), "key");
  EXPECT_EQ(select->ColumnInt(1), int64_t{1} << 40);
  EXPECT_EQ(select->ColumnDouble(2), 0.25);
  EXPECT_EQ(select->ColumnBlob(3), std::string("a\0b", 3));
  row = select->Step();
  ASSERT_TRUE(row.ok());
  EXPECT_FALSE(*row);
}

TEST(DatabaseTest, FreedPagesGoBackToTheFileSystem) {
  const std::string path = TempPath("vacuum.db");
  auto db = Database::Open(path);
  ASSERT_TRUE(db.ok()) << db.status();
  ASSERT_TRUE((*db)->Execute("CREATE TABLE t (x BLOB); INSERT INTO t VALUES (zeroblob(8000000)); "
                             "PRAGMA wal_checkpoint(TRUNCATE)")
                  .ok());
  const auto grown = std::filesystem::file_size(path);
  EXPECT_GT(grown, 8000000u);
  ASSERT_TRUE((*db)->Execute("UPDATE t SET x = NULL; PRAGMA incremental_vacuum; "
                             "PRAGMA wal_checkpoint(TRUNCATE)")
                  .ok());
  EXPECT_LT(std::filesystem::file_size(path), grown / 10);
}

TEST(DatabaseTest, ErrorsNameTheDatabaseAndTheStatement) {
  auto db = Database::Open(TempPath("sqlite_db_test_errors.db"));
  ASSERT_TRUE(db.ok());
  const absl::Status bad = (*db)->Execute("SELECT * FROM missing_table");
  EXPECT_EQ(bad.code(), absl::StatusCode::kInternal);
  EXPECT_NE(bad.message().find("missing_table"), std::string::npos) << bad;
  EXPECT_NE(bad.message().find("sqlite_db_test_errors.db"), std::string::npos) << bad;
  ASSERT_TRUE((*db)->Execute("CREATE TABLE u (k TEXT PRIMARY KEY)").ok());
  auto insert = (*db)->Prepare("INSERT INTO u VALUES (?)");
  ASSERT_TRUE(insert->Bind(1, "x").Run().ok());
  insert->Reset();
  EXPECT_FALSE(insert->Bind(1, "x").Run().ok());  // primary key conflict is reported
}

TEST(DatabaseTest, OpenFailsWithThePath) {
  auto db = Database::Open("/nonexistent-dir/x/y.db");
  ASSERT_FALSE(db.ok());
  EXPECT_NE(db.status().message().find("/nonexistent-dir/x/y.db"), std::string::npos);
}

TEST(TransactionTest, CommitKeepsAndAnEarlyEndRollsBack) {
  const std::string path = TempPath("sqlite_db_test_transaction.db");
  auto db = Database::Open(path);
  ASSERT_TRUE(db.ok());
  ASSERT_TRUE((*db)->Execute("CREATE TABLE t (v INTEGER)").ok());
  {
    auto transaction = Transaction::Begin(db->get());
    ASSERT_TRUE(transaction.ok());
    ASSERT_TRUE((*db)->Execute("INSERT INTO t VALUES (1)").ok());
    ASSERT_TRUE(transaction->Commit().ok());
    EXPECT_FALSE(transaction->Commit().ok());  // once
  }
  {
    auto transaction = Transaction::Begin(db->get());
    ASSERT_TRUE(transaction.ok());
    ASSERT_TRUE((*db)->Execute("INSERT INTO t VALUES (2)").ok());
  }  // destroyed uncommitted: as if an error had returned early
  auto count = (*db)->Prepare("SELECT COUNT(*), SUM(v) FROM t");
  ASSERT_TRUE(count.ok());
  ASSERT_TRUE(count->Run().ok());
  EXPECT_EQ(count->ColumnInt(0), 1);
  EXPECT_EQ(count->ColumnInt(1), 1);
  EXPECT_EQ((*db)->UserVersion().value(), 0);
  ASSERT_TRUE((*db)->SetUserVersion(7).ok());
  EXPECT_EQ((*db)->UserVersion().value(), 7);
}

}  // namespace
}  // namespace meshseek
