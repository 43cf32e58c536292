#include "services/coordinator/coordinator_store.h"

#include <algorithm>
#include <filesystem>
#include <limits>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "common/base/logging.h"
#include "common/base/status_macros.h"
#include "services/coordinator/coordinator_schema.h"

namespace meshseek {
namespace {

constexpr int kMaxJobErrors = 20;

}  // namespace

v1::ModelState ToProto(ModelState state) {
  switch (state) {
    case ModelState::kPending:
      return v1::MODEL_STATE_PENDING;
    case ModelState::kExtracted:
      return v1::MODEL_STATE_EXTRACTED;
    case ModelState::kFailed:
      return v1::MODEL_STATE_FAILED;
  }
  return v1::MODEL_STATE_UNSPECIFIED;
}

absl::StatusOr<std::unique_ptr<CoordinatorStore>> CoordinatorStore::Open(
    const std::string& data_dir, int index_shards) {
  std::error_code error;
  std::filesystem::create_directories(data_dir, error);
  MESHSEEK_ASSIGN_OR_RETURN(std::unique_ptr<Database> db,
                            Database::Open(data_dir + "/coordinator.db"));
  MESHSEEK_ASSIGN_OR_RETURN(FeatureFiles features, FeatureFiles::Open(data_dir + "/features"));
  std::unique_ptr<CoordinatorStore> store(
      new CoordinatorStore(std::move(db), std::move(features)));
  absl::MutexLock lock(&store->mutex_);
  MESHSEEK_RETURN_IF_ERROR(store->Migrate(index_shards));
  return store;
}

// Releases before feature files kept features in models.features: each
// moves to its file, then the column is emptied and the pages given back.
// The file is written before the row lets go, so a kill midway loses none.
absl::Status CoordinatorStore::MoveFeaturesOutOfRows() {
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT collection, model_id, features FROM models WHERE features IS NOT NULL"));
  uint64_t moved = 0;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) break;
    MESHSEEK_RETURN_IF_ERROR(
        features_.Put(select.ColumnText(0), select.ColumnText(1), select.ColumnBlob(2)));
    ++moved;
  }
  select.Reset();
  if (moved == 0) return absl::OkStatus();
  MESHSEEK_RETURN_IF_ERROR(
      db_->Execute("UPDATE models SET features = NULL WHERE features IS NOT NULL"));
  MESHSEEK_LOG(INFO) << db_->path() << ": features of " << moved << " models moved to "
                     << features_.dir();
  // A no-op in files of releases before auto_vacuum, which reuse the pages.
  return db_->Execute("PRAGMA incremental_vacuum");
}

absl::Status CoordinatorStore::Migrate(int index_shards) {
  MESHSEEK_RETURN_IF_ERROR(MigrateCoordinatorSchema(db_.get()));
  MESHSEEK_RETURN_IF_ERROR(MoveFeaturesOutOfRows());
  // Models are placed on index shards by hash modulo their number: another
  // number would look for every model on the wrong shard.
  {
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement shards,
        db_->Prepare("INSERT INTO settings (key, value) VALUES ('index_shards', ?) "
                     "ON CONFLICT (key) DO UPDATE SET value = value RETURNING value"));
    shards.Bind(1, int64_t{index_shards});
    MESHSEEK_ASSIGN_OR_RETURN(const bool stored, shards.Step());
    if (stored && shards.ColumnInt(0) != index_shards) {
      return absl::FailedPreconditionError(absl::StrCat(
          std::filesystem::path(db_->path()).parent_path().string(), " was used with ",
          shards.ColumnInt(0), " index shards, --index lists ", index_shards,
          "; models would be looked for on the wrong shards"));
    }
  }  // finalized: a statement left in progress would block the COMMIT below
  // Streams do not survive a restart; their models do.
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  MESHSEEK_RETURN_IF_ERROR(db_->Execute("UPDATE jobs SET stream_open = 0"));
  std::vector<std::string> ingests;
  {
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement running,
        db_->Prepare("SELECT id FROM jobs WHERE kind = 'ingest' AND state = ?"));
    running.Bind(1, int64_t{v1::JOB_STATE_RUNNING});
    while (true) {
      MESHSEEK_ASSIGN_OR_RETURN(const bool row, running.Step());
      if (!row) break;
      ingests.push_back(running.ColumnText(0));
    }
  }
  for (const std::string& job : ingests) MESHSEEK_RETURN_IF_ERROR(FinishIngestJobIfDone(job));
  return transaction.Commit();
}

// ---------------------------------------------------------------- collections

absl::StatusOr<StoredCollection> CoordinatorStore::GetCollection(const std::string& name) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select, db_->Prepare("SELECT params, codebook_id FROM collections WHERE name = ?"));
  select.Bind(1, name);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("no collection '", name, "'"));
  StoredCollection collection;
  if (!collection.params.ParseFromString(select.ColumnBlob(0))) {
    return absl::DataLossError(absl::StrCat("collection '", name, "': stored parameters do not parse"));
  }
  collection.codebook_id = select.ColumnText(1);
  return collection;
}

absl::Status CoordinatorStore::CreateCollections(
    const std::vector<std::pair<std::string, v1::PipelineParams>>& collections) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  for (const auto& [name, params] : collections) {
    const std::string bytes = params.SerializeAsString();
    MESHSEEK_ASSIGN_OR_RETURN(Statement select,
                              db_->Prepare("SELECT params FROM collections WHERE name = ?"));
    select.Bind(1, name);
    MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
    if (found) {
      if (select.ColumnBlob(0) == bytes) continue;
      return absl::AlreadyExistsError(
          absl::StrCat("collection '", name, "' exists with other parameters"));
    }
    select.Reset();
    MESHSEEK_ASSIGN_OR_RETURN(Statement insert,
                              db_->Prepare("INSERT INTO collections (name, params) VALUES (?, ?)"));
    MESHSEEK_RETURN_IF_ERROR(insert.Bind(1, name).BindBlob(2, bytes).Run());
  }
  return transaction.Commit();
}

absl::Status CoordinatorStore::SetCodebook(const std::string& collection,
                                           const std::string& codebook_id) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Statement update,
                            db_->Prepare("UPDATE collections SET codebook_id = ? WHERE name = ?"));
  return update.Bind(1, codebook_id).Bind(2, collection).Run();
}

absl::StatusOr<ModelCounts> CoordinatorStore::CountModels(
    const std::vector<std::string>& collections, const std::string& build) {
  absl::MutexLock lock(&mutex_);
  // Each model once over all its rows (one, or one per member of a fused
  // collection): extracted and indexed only when it is in every one.
  std::string in;
  for (std::size_t i = 0; i < collections.size(); ++i) absl::StrAppend(&in, i ? ", ?" : "?");
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement count,
      db_->Prepare(absl::StrCat(
          "SELECT COUNT(*), SUM(failed = 0 AND pending), SUM(failed = 0 AND extracted), "
          "SUM(failed), SUM(failed = 0 AND indexed), SUM(failed = 0 AND indexed AND live) "
          "FROM (SELECT MAX(state = 2) AS failed, "
          "MAX(state = 0) AS pending, MIN(state = 1) AND COUNT(*) = ? AS extracted, "
          "MIN(state = 1 AND indexed_codebook = collection || '@' || ?) AND COUNT(*) = ? "
          "AS indexed, MAX(live) AS live FROM models WHERE collection IN (",
          in,
          ") GROUP BY model_id)")));
  count.Bind(1, static_cast<int64_t>(collections.size()))
      .Bind(2, build)
      .Bind(3, static_cast<int64_t>(collections.size()));
  for (std::size_t i = 0; i < collections.size(); ++i) {
    count.Bind(static_cast<int>(i) + 4, collections[i]);
  }
  MESHSEEK_RETURN_IF_ERROR(count.Run());
  ModelCounts counts;
  counts.models = count.ColumnInt(0);
  counts.pending = count.ColumnInt(1);
  counts.extracted = count.ColumnInt(2);
  counts.failed = count.ColumnInt(3);
  counts.indexed = build.empty() ? 0 : count.ColumnInt(4);
  counts.added = build.empty() ? 0 : count.ColumnInt(5);
  return counts;
}

// ----------------------------------------------------------------------- jobs

absl::StatusOr<std::string> CoordinatorStore::NewJob(const std::string& kind,
                                                     const std::string& collection,
                                                     uint64_t total) {
  absl::MutexLock lock(&mutex_);
  // The row and its id together: a crash between them would leave a job
  // nobody can name.
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement insert,
      db_->Prepare("INSERT INTO jobs (kind, collection, state, total, stream_open) "
                   "VALUES (?, ?, ?, ?, ?) RETURNING seq"));
  insert.Bind(1, kind)
      .Bind(2, collection)
      .Bind(3, int64_t{v1::JOB_STATE_RUNNING})
      .Bind(4, static_cast<int64_t>(total))
      .Bind(5, int64_t{kind == "ingest"});
  MESHSEEK_ASSIGN_OR_RETURN(const bool inserted, insert.Step());
  if (!inserted) return absl::InternalError("jobs: INSERT returned no row");
  const int64_t seq = insert.ColumnInt(0);
  insert.Reset();
  const std::string id = absl::StrCat(kind, "-", seq);
  MESHSEEK_ASSIGN_OR_RETURN(Statement name, db_->Prepare("UPDATE jobs SET id = ? WHERE seq = ?"));
  MESHSEEK_RETURN_IF_ERROR(name.Bind(1, id).Bind(2, seq).Run());
  MESHSEEK_RETURN_IF_ERROR(transaction.Commit());
  return id;
}

absl::Status CoordinatorStore::FinishJob(const std::string& job_id,
                                         v1::JobState state,
                                         const std::string& message) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement update, db_->Prepare("UPDATE jobs SET state = ?, message = ? WHERE id = ?"));
  return update.Bind(1, int64_t{state}).Bind(2, message).Bind(3, job_id).Run();
}

absl::Status CoordinatorStore::CloseIngestStream(const std::string& job_id) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  MESHSEEK_ASSIGN_OR_RETURN(Statement close,
                            db_->Prepare("UPDATE jobs SET stream_open = 0 WHERE id = ?"));
  MESHSEEK_RETURN_IF_ERROR(close.Bind(1, job_id).Run());
  MESHSEEK_RETURN_IF_ERROR(FinishIngestJobIfDone(job_id));
  return transaction.Commit();
}

absl::Status CoordinatorStore::FinishIngestJobIfDone(const std::string& job_id) {
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement job, db_->Prepare("SELECT kind, state, stream_open FROM jobs WHERE id = ?"));
  job.Bind(1, job_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, job.Step());
  if (!found || job.ColumnText(0) != "ingest" || job.ColumnInt(1) != v1::JOB_STATE_RUNNING ||
      job.ColumnInt(2) != 0) {
    return absl::OkStatus();
  }
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement count, db_->Prepare("SELECT COUNT(*), SUM(state = 0), SUM(state = 2) "
                                    "FROM models WHERE job_id = ?"));
  count.Bind(1, job_id);
  MESHSEEK_RETURN_IF_ERROR(count.Run());
  const int64_t total = count.ColumnInt(0), pending = count.ColumnInt(1),
                failed = count.ColumnInt(2);
  if (pending > 0) return absl::OkStatus();
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement finish, db_->Prepare("UPDATE jobs SET state = ?, message = ? WHERE id = ?"));
  return finish.Bind(1, int64_t{failed > 0 ? v1::JOB_STATE_FAILED : v1::JOB_STATE_SUCCEEDED})
      .Bind(2, failed > 0 ? absl::StrCat(failed, " of ", total, " models failed")
                          : absl::StrCat(total, " models extracted"))
      .Bind(3, job_id)
      .Run();
}

absl::StatusOr<v1::JobStatus> CoordinatorStore::GetJob(const std::string& job_id) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement job,
      db_->Prepare("SELECT kind, collection, state, message, total FROM jobs WHERE id = ?"));
  job.Bind(1, job_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, job.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("no job '", job_id, "'"));
  v1::JobStatus status;
  status.set_job_id(job_id);
  status.set_kind(job.ColumnText(0));
  status.set_collection(job.ColumnText(1));
  status.set_state(static_cast<v1::JobState>(job.ColumnInt(2)));
  status.set_message(job.ColumnText(3));
  if (status.kind() != "ingest") {
    status.set_total(job.ColumnInt(4));
    // Models of the collection, or of its members ("<collection>~<method>":
    // collection names have no glob characters), indexed by this job.
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement count,
        db_->Prepare("SELECT COUNT(*) FROM models WHERE (collection = ?1 OR collection GLOB "
                     "?1 || '~*') AND state = 1 AND indexed_codebook = collection || '@' || ?2"));
    count.Bind(1, status.collection()).Bind(2, job_id);
    MESHSEEK_RETURN_IF_ERROR(count.Run());
    status.set_done(std::min<uint64_t>(count.ColumnInt(0), status.total()));
    return status;
  }
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement count, db_->Prepare("SELECT COUNT(*), SUM(state != 0), SUM(state = 2) "
                                    "FROM models WHERE job_id = ?"));
  count.Bind(1, job_id);
  MESHSEEK_RETURN_IF_ERROR(count.Run());
  status.set_total(count.ColumnInt(0));
  status.set_done(count.ColumnInt(1));
  status.set_failed(count.ColumnInt(2));
  if (status.failed() == 0) return status;
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement errors, db_->Prepare("SELECT model_id, error FROM models WHERE job_id = ? "
                                     "AND state = 2 ORDER BY ordinal LIMIT ?"));
  errors.Bind(1, job_id).Bind(2, int64_t{kMaxJobErrors});
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, errors.Step());
    if (!row) break;
    status.add_errors(absl::StrCat("model ", errors.ColumnText(0), ": ", errors.ColumnText(1)));
  }
  return status;
}

absl::StatusOr<std::vector<std::pair<std::string, std::string>>> CoordinatorStore::RunningBuilds() {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select, db_->Prepare("SELECT id, collection FROM jobs WHERE kind = 'build' "
                                     "AND state = ? ORDER BY seq"));
  select.Bind(1, int64_t{v1::JOB_STATE_RUNNING});
  std::vector<std::pair<std::string, std::string>> builds;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) return builds;
    builds.emplace_back(select.ColumnText(0), select.ColumnText(1));
  }
}

}  // namespace meshseek
