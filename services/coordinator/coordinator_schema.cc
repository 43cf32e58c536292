#include "services/coordinator/coordinator_schema.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "common/base/hash.h"
#include "common/base/logging.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

// Version 1: the first release's schema, as it created it.
constexpr const char* kSchema1 = R"sql(
  CREATE TABLE IF NOT EXISTS collections (
    name TEXT PRIMARY KEY, params BLOB NOT NULL, codebook_id TEXT NOT NULL DEFAULT '');
  CREATE TABLE IF NOT EXISTS models (
    collection TEXT NOT NULL, model_id TEXT NOT NULL, ordinal INTEGER NOT NULL,
    label TEXT NOT NULL, mesh BLOB NOT NULL, fingerprint TEXT NOT NULL,
    state INTEGER NOT NULL, error TEXT NOT NULL DEFAULT '', features BLOB,
    feature_count INTEGER NOT NULL DEFAULT 0, job_id TEXT NOT NULL,
    indexed_codebook TEXT NOT NULL DEFAULT '',
    PRIMARY KEY (collection, model_id));
  CREATE INDEX IF NOT EXISTS models_by_state ON models (state);
  CREATE TABLE IF NOT EXISTS jobs (
    seq INTEGER PRIMARY KEY AUTOINCREMENT, id TEXT UNIQUE, kind TEXT NOT NULL,
    collection TEXT NOT NULL, state INTEGER NOT NULL, message TEXT NOT NULL DEFAULT '',
    total INTEGER NOT NULL DEFAULT 0, stream_open INTEGER NOT NULL DEFAULT 0);
  CREATE TABLE IF NOT EXISTS settings (key TEXT PRIMARY KEY, value INTEGER NOT NULL);
)sql";

// Version 2: attempts and backoff per model (retry_at in Unix microseconds,
// 0 = now), and indexes on what is scanned: the dispatchers' claim (state,
// retry_at), a job's counts (job_id), a collection's models in order, all or
// in one state (ListModels pages).
constexpr const char* kSchema2 = R"sql(
  ALTER TABLE models ADD COLUMN attempts INTEGER NOT NULL DEFAULT 0;
  ALTER TABLE models ADD COLUMN retry_at INTEGER NOT NULL DEFAULT 0;
  DROP INDEX IF EXISTS models_by_state;
  CREATE INDEX models_claim ON models (state, retry_at);
  CREATE INDEX models_by_job ON models (job_id, state);
  CREATE INDEX models_in_order ON models (collection, ordinal);
  CREATE INDEX models_by_state_in_order ON models (collection, state, ordinal);
)sql";

// Version 3: the ranking state of fused and re-ranked collections.
constexpr const char* kSchema3 = R"sql(
  CREATE TABLE rankings (
    collection TEXT PRIMARY KEY, build TEXT NOT NULL, state BLOB NOT NULL);
)sql";

// Version 1 fingerprinted meshes with the mistaken FNV basis: recompute them,
// or every retried ingest of an old model would be "another mesh".
absl::Status RecomputeFingerprints(Database* db) {
  MESHSEEK_ASSIGN_OR_RETURN(Statement select, db->Prepare("SELECT rowid, mesh FROM models"));
  MESHSEEK_ASSIGN_OR_RETURN(Statement update,
                            db->Prepare("UPDATE models SET fingerprint = ? WHERE rowid = ?"));
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) return absl::OkStatus();
    update.Reset();
    MESHSEEK_RETURN_IF_ERROR(
        update.Bind(1, MeshFingerprint(select.ColumnBlob(1))).Bind(2, select.ColumnInt(0)).Run());
  }
}

// Version 4: a thumbnail per model (PNG), under the collection clients name
// (a fused collection's, not its members').
constexpr const char* kSchema4 = R"sql(
  CREATE TABLE thumbnails (
    collection TEXT NOT NULL, model_id TEXT NOT NULL, png BLOB NOT NULL,
    PRIMARY KEY (collection, model_id));
)sql";

// Version 5: live ingest (docs/design.md "Live ingest"). `live` marks a
// model indexed with its collection's codebook after the build that trained
// it (status counts them: added since the codebook); ranking_joins holds,
// per fused or re-ranked collection, the models that joined its build's
// ranking state since, in join order (seq), each a RankingJoin.
constexpr const char* kSchema5 = R"sql(
  ALTER TABLE models ADD COLUMN live INTEGER NOT NULL DEFAULT 0;
  CREATE TABLE ranking_joins (
    collection TEXT NOT NULL, seq INTEGER NOT NULL, build TEXT NOT NULL,
    model_id TEXT NOT NULL, node BLOB NOT NULL, PRIMARY KEY (collection, seq));
)sql";

}  // namespace

std::string MeshFingerprint(const std::string& mesh_bytes) {
  return absl::StrCat(absl::Hex(Fnv1a64(mesh_bytes), absl::kZeroPad16));
}

absl::Status MigrateCoordinatorSchema(Database* db) {
  MESHSEEK_ASSIGN_OR_RETURN(const int64_t version, db->UserVersion());
  if (version > kCoordinatorSchemaVersion) {
    return absl::FailedPreconditionError(
        absl::StrCat(db->path(), " has schema version ", version, "; this coordinator knows up to ",
                     kCoordinatorSchemaVersion, " (a newer release wrote it)"));
  }
  for (int64_t to = std::max<int64_t>(version, 0) + 1; to <= kCoordinatorSchemaVersion; ++to) {
    MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db));
    if (to == 1) MESHSEEK_RETURN_IF_ERROR(db->Execute(kSchema1));
    if (to == 2) {
      MESHSEEK_RETURN_IF_ERROR(db->Execute(kSchema2));
      MESHSEEK_RETURN_IF_ERROR(RecomputeFingerprints(db));
    }
    if (to == 3) MESHSEEK_RETURN_IF_ERROR(db->Execute(kSchema3));
    if (to == 4) MESHSEEK_RETURN_IF_ERROR(db->Execute(kSchema4));
    if (to == 5) MESHSEEK_RETURN_IF_ERROR(db->Execute(kSchema5));
    MESHSEEK_RETURN_IF_ERROR(db->SetUserVersion(to));
    MESHSEEK_RETURN_IF_ERROR(transaction.Commit());
    if (version > 0) MESHSEEK_LOG(INFO) << db->path() << ": schema migrated to version " << to;
  }
  return absl::OkStatus();
}

}  // namespace meshseek
