// The coordinator database's schema and its versions (PRAGMA user_version),
// migrated in order, each step in one transaction:
//   1  the first release's tables (created IF NOT EXISTS, so a database of
//      that release, which stored no version, is taken as version 1);
//   2  per-model attempts and retry time, indexes for what the dispatchers
//      and job counts scan, and mesh fingerprints recomputed with the correct
//      FNV-1a offset basis (version 1 used one a digit short);
//   3  rankings: what the build of a fused or re-ranked collection leaves for
//      its queries (each method's scale, the models in node order, the
//      neighbour graph), one row per collection.
// A database of a newer version than this code knows is refused.
#ifndef MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SCHEMA_H_
#define MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SCHEMA_H_

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "common/store/sqlite_db.h"

namespace meshseek {

/// The schema version this code writes.
inline constexpr int64_t kCoordinatorSchemaVersion = 5;

/// Brings `db` to kCoordinatorSchemaVersion; FailedPrecondition for a newer
/// one.
absl::Status MigrateCoordinatorSchema(Database* db);

/// FNV-1a 64 of a stored mesh as 16 hex digits: tells a retried ingest from a
/// different model under the same id.
std::string MeshFingerprint(const std::string& mesh_bytes);

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SCHEMA_H_
