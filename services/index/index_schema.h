// The index database's schema and its versions (PRAGMA user_version), migrated
// in order, each step in one transaction, as the coordinator's
// (coordinator_schema.h):
//   1  the first release's table: one row per (collection, model id) with
//      its ordinal, label and serialised SparseHistogram (created IF NOT
//      EXISTS, so a database of that release, which stored no version, is
//      taken as version 1);
//   2  a serialised GlobalDescriptor per row (empty for a histogram), for the
//      collections of a global method (LFD). Releases before versioning added
//      this column in place, so the step adds it only where it is missing.
// A database of a newer version than this code knows is refused.
#ifndef MESHSEEK_SERVICES_INDEX_INDEX_SCHEMA_H_
#define MESHSEEK_SERVICES_INDEX_INDEX_SCHEMA_H_

#include <cstdint>

#include "absl/status/status.h"
#include "common/store/sqlite_db.h"

namespace meshseek {

/// The schema version this code writes.
inline constexpr int64_t kIndexSchemaVersion = 2;

/// Brings `db` to kIndexSchemaVersion; FailedPrecondition for a newer one.
absl::Status MigrateIndexSchema(Database* db);

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_INDEX_INDEX_SCHEMA_H_
