#include "services/index/index_schema.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "common/base/logging.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

constexpr const char* kSchema1 = R"sql(
  CREATE TABLE IF NOT EXISTS models (
    collection TEXT NOT NULL, model_id TEXT NOT NULL, ordinal INTEGER NOT NULL,
    label TEXT NOT NULL, histogram BLOB NOT NULL, PRIMARY KEY (collection, model_id));
)sql";

absl::Status AddDescriptorColumn(Database* db) {
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement has_descriptor,
      db->Prepare("SELECT COUNT(*) FROM pragma_table_info('models') WHERE name = 'descriptor'"));
  MESHSEEK_RETURN_IF_ERROR(has_descriptor.Step().status());
  if (has_descriptor.ColumnInt(0) > 0) return absl::OkStatus();
  return db->Execute("ALTER TABLE models ADD COLUMN descriptor BLOB NOT NULL DEFAULT x''");
}

}  // namespace

absl::Status MigrateIndexSchema(Database* db) {
  MESHSEEK_ASSIGN_OR_RETURN(const int64_t version, db->UserVersion());
  if (version > kIndexSchemaVersion) {
    return absl::FailedPreconditionError(
        absl::StrCat(db->path(), " has schema version ", version, "; this index knows up to ",
                     kIndexSchemaVersion, " (a newer release wrote it)"));
  }
  for (int64_t to = std::max<int64_t>(version, 0) + 1; to <= kIndexSchemaVersion; ++to) {
    MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db));
    if (to == 1) MESHSEEK_RETURN_IF_ERROR(db->Execute(kSchema1));
    if (to == 2) MESHSEEK_RETURN_IF_ERROR(AddDescriptorColumn(db));
    MESHSEEK_RETURN_IF_ERROR(db->SetUserVersion(to));
    MESHSEEK_RETURN_IF_ERROR(transaction.Commit());
    if (version > 0) MESHSEEK_LOG(INFO) << db->path() << ": schema migrated to version " << to;
  }
  return absl::OkStatus();
}

}  // namespace meshseek
