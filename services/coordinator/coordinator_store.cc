#include "services/coordinator/coordinator_store.h"

#include <algorithm>
#include <filesystem>
#include <limits>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "services/coordinator/coordinator_schema.h"

namespace meshseek {
namespace {

constexpr int kMaxJobErrors = 20;
constexpr uint32_t kDefaultPageSize = 100;
constexpr uint32_t kMaxPageSize = 1000;

int64_t ToMicros(absl::Time t) { return absl::ToUnixMicros(t); }

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
  std::unique_ptr<CoordinatorStore> store(new CoordinatorStore(std::move(db)));
  absl::MutexLock lock(&store->mutex_);
  MESHSEEK_RETURN_IF_ERROR(store->Migrate(index_shards));
  return store;
}

absl::Status CoordinatorStore::Migrate(int index_shards) {
  MESHSEEK_RETURN_IF_ERROR(MigrateCoordinatorSchema(db_.get()));
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

absl::Status CoordinatorStore::CreateCollection(const std::string& name,
                                                const v1::PipelineParams& params) {
  const std::string bytes = params.SerializeAsString();
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Statement select,
                            db_->Prepare("SELECT params FROM collections WHERE name = ?"));
  select.Bind(1, name);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (found) {
    if (select.ColumnBlob(0) == bytes) return absl::OkStatus();
    return absl::AlreadyExistsError(
        absl::StrCat("collection '", name, "' exists with other parameters"));
  }
  MESHSEEK_ASSIGN_OR_RETURN(Statement insert,
                            db_->Prepare("INSERT INTO collections (name, params) VALUES (?, ?)"));
  return insert.Bind(1, name).BindBlob(2, bytes).Run();
}

absl::Status CoordinatorStore::SetCodebook(const std::string& collection,
                                           const std::string& codebook_id) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Statement update,
                            db_->Prepare("UPDATE collections SET codebook_id = ? WHERE name = ?"));
  return update.Bind(1, codebook_id).Bind(2, collection).Run();
}

absl::StatusOr<ModelCounts> CoordinatorStore::CountModels(const std::string& collection,
                                                          const std::string& codebook_id) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement count,
      db_->Prepare("SELECT COUNT(*), SUM(state = 0), SUM(state = 1), SUM(state = 2), "
                   "SUM(state = 1 AND indexed_codebook = ?) FROM models WHERE collection = ?"));
  count.Bind(1, codebook_id).Bind(2, collection);
  MESHSEEK_RETURN_IF_ERROR(count.Run());
  ModelCounts counts;
  counts.models = count.ColumnInt(0);
  counts.pending = count.ColumnInt(1);
  counts.extracted = count.ColumnInt(2);
  counts.failed = count.ColumnInt(3);
  counts.indexed = codebook_id.empty() ? 0 : count.ColumnInt(4);
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
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement count, db_->Prepare("SELECT COUNT(*) FROM models WHERE collection = ? "
                                      "AND state = 1 AND indexed_codebook = ?"));
    count.Bind(1, status.collection()).Bind(2, absl::StrCat(status.collection(), "@", job_id));
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

// --------------------------------------------------------------------- models

absl::StatusOr<CoordinatorStore::AddedModel> CoordinatorStore::AddModel(
    const ModelKey& key, const std::string& label, const std::string& mesh,
    const std::string& job_id) {
  const std::string fingerprint = MeshFingerprint(mesh);
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement existing, db_->Prepare("SELECT fingerprint, label, job_id FROM models "
                                       "WHERE collection = ? AND model_id = ?"));
  existing.Bind(1, key.collection).Bind(2, key.model_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, existing.Step());
  if (found) {
    if (existing.ColumnText(0) != fingerprint || existing.ColumnText(1) != label) {
      return absl::AlreadyExistsError(
          absl::StrCat("model ", key.model_id, " exists in collection '", key.collection,
                       "' with another mesh or label; remove it first"));
    }
    return AddedModel{false, existing.ColumnText(2)};
  }
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement insert,
      db_->Prepare("INSERT INTO models (collection, model_id, ordinal, label, mesh, fingerprint, "
                   "state, job_id) VALUES (?1, ?2, (SELECT COALESCE(MAX(ordinal), -1) + 1 FROM "
                   "models WHERE collection = ?1), ?3, ?4, ?5, 0, ?6)"));
  MESHSEEK_RETURN_IF_ERROR(insert.Bind(1, key.collection)
                               .Bind(2, key.model_id)
                               .Bind(3, label)
                               .BindBlob(4, mesh)
                               .Bind(5, fingerprint)
                               .Bind(6, job_id)
                               .Run());
  return AddedModel{true, job_id};
}

absl::StatusOr<std::vector<ModelKey>> CoordinatorStore::ClaimablePending(
    absl::Time now, const std::vector<ModelKey>& busy, int limit) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT collection, model_id FROM models WHERE state = 0 AND retry_at <= ? "
                   "ORDER BY retry_at, rowid LIMIT ?"));
  select.Bind(1, ToMicros(now)).Bind(2, static_cast<int64_t>(busy.size()) + limit);
  std::vector<ModelKey> keys;
  while (static_cast<int>(keys.size()) < limit) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) break;
    ModelKey key{select.ColumnText(0), select.ColumnText(1)};
    if (std::find(busy.begin(), busy.end(), key) == busy.end()) keys.push_back(std::move(key));
  }
  return keys;
}

absl::StatusOr<std::optional<absl::Time>> CoordinatorStore::NextRetry(absl::Time now) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT MIN(retry_at) FROM models WHERE state = 0 AND retry_at > ?"));
  select.Bind(1, ToMicros(now));
  MESHSEEK_RETURN_IF_ERROR(select.Run());
  if (select.ColumnIsNull(0)) return std::nullopt;
  return absl::FromUnixMicros(select.ColumnInt(0));
}

absl::StatusOr<std::optional<PendingModel>> CoordinatorStore::LoadPending(const ModelKey& key) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select, db_->Prepare("SELECT mesh, ordinal, label, attempts, job_id FROM models "
                                     "WHERE collection = ? AND model_id = ? AND state = 0"));
  select.Bind(1, key.collection).Bind(2, key.model_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (!found) return std::nullopt;
  PendingModel model;
  model.mesh = select.ColumnBlob(0);
  model.ordinal = static_cast<uint64_t>(select.ColumnInt(1));
  model.label = select.ColumnText(2);
  model.attempts = static_cast<int>(select.ColumnInt(3));
  model.job_id = select.ColumnText(4);
  return model;
}

uint64_t CoordinatorStore::PendingCount() {
  absl::MutexLock lock(&mutex_);
  absl::StatusOr<Statement> count = db_->Prepare("SELECT COUNT(*) FROM models WHERE state = 0");
  if (!count.ok() || !count->Run().ok()) return 0;
  return static_cast<uint64_t>(count->ColumnInt(0));
}

absl::StatusOr<bool> CoordinatorStore::MarkExtracted(const ModelKey& key,
                                                     const std::string& features,
                                                     uint32_t feature_count) {
  return EndPending(key, ModelState::kExtracted, -1, "", features, feature_count);
}

absl::StatusOr<bool> CoordinatorStore::MarkFailed(const ModelKey& key, int attempts,
                                                  const std::string& reason) {
  return EndPending(key, ModelState::kFailed, attempts, reason, "", 0);
}

absl::StatusOr<bool> CoordinatorStore::EndPending(const ModelKey& key, ModelState state,
                                                  int attempts, const std::string& error,
                                                  const std::string& features,
                                                  uint32_t feature_count) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement update,
      db_->Prepare("UPDATE models SET state = ?, error = ?, features = ?, feature_count = ?, "
                   "attempts = CASE WHEN ? < 0 THEN attempts + 1 ELSE ? END, retry_at = 0 "
                   "WHERE collection = ? AND model_id = ? AND state = 0 RETURNING job_id"));
  update.Bind(1, static_cast<int64_t>(state))
      .Bind(2, error)
      .BindBlob(3, features)
      .Bind(4, int64_t{feature_count})
      .Bind(5, int64_t{attempts})
      .Bind(6, int64_t{attempts})
      .Bind(7, key.collection)
      .Bind(8, key.model_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool changed, update.Step());
  if (!changed) return false;
  const std::string job_id = update.ColumnText(0);
  update.Reset();
  MESHSEEK_RETURN_IF_ERROR(FinishIngestJobIfDone(job_id));
  MESHSEEK_RETURN_IF_ERROR(transaction.Commit());
  return true;
}

absl::Status CoordinatorStore::ScheduleRetry(const ModelKey& key, int attempts,
                                             absl::Time retry_at, const std::string& error) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement update,
      db_->Prepare("UPDATE models SET attempts = ?, retry_at = ?, error = ? "
                   "WHERE collection = ? AND model_id = ? AND state = 0"));
  return update.Bind(1, int64_t{attempts})
      .Bind(2, ToMicros(retry_at))
      .Bind(3, error)
      .Bind(4, key.collection)
      .Bind(5, key.model_id)
      .Run();
}

absl::Status CoordinatorStore::MarkIndexed(const ModelKey& key, const std::string& codebook_id) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement mark, db_->Prepare("UPDATE models SET indexed_codebook = ? WHERE collection = ? "
                                   "AND model_id = ?"));
  return mark.Bind(1, codebook_id).Bind(2, key.collection).Bind(3, key.model_id).Run();
}

absl::StatusOr<std::optional<ModelState>> CoordinatorStore::RemoveModel(const ModelKey& key) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement erase, db_->Prepare("DELETE FROM models WHERE collection = ? AND model_id = ? "
                                    "RETURNING state, job_id"));
  erase.Bind(1, key.collection).Bind(2, key.model_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, erase.Step());
  if (!found) return std::nullopt;
  const auto state = static_cast<ModelState>(erase.ColumnInt(0));
  const std::string job_id = erase.ColumnText(1);
  erase.Reset();
  // The removed model may have been the last its ingest job waited for.
  MESHSEEK_RETURN_IF_ERROR(FinishIngestJobIfDone(job_id));
  MESHSEEK_RETURN_IF_ERROR(transaction.Commit());
  return state;
}

absl::StatusOr<std::vector<ExtractedModel>> CoordinatorStore::ExtractedModels(
    const std::string& collection) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT model_id, ordinal, label, features, indexed_codebook FROM models "
                   "WHERE collection = ? AND state = 1 ORDER BY ordinal"));
  select.Bind(1, collection);
  std::vector<ExtractedModel> models;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) return models;
    models.push_back({select.ColumnText(0), static_cast<uint64_t>(select.ColumnInt(1)),
                      select.ColumnText(2), select.ColumnBlob(3), select.ColumnText(4)});
  }
}

absl::StatusOr<v1::ListCollectionModelsResponse> CoordinatorStore::ListModels(
    const v1::ListCollectionModelsRequest& request) {
  const uint32_t page_size = request.page_size() == 0 ? kDefaultPageSize : request.page_size();
  if (page_size > kMaxPageSize) {
    return absl::InvalidArgumentError(
        absl::StrCat("list models: page_size ", page_size, " is more than ", kMaxPageSize));
  }
  int64_t after = -1;
  if (!request.page_token().empty() &&
      (!absl::SimpleAtoi(request.page_token(), &after) || after < 0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("list models: page_token '", request.page_token(), "' is not one we gave"));
  }
  int64_t state = -1;
  switch (request.state()) {
    case v1::MODEL_STATE_UNSPECIFIED:
      break;
    case v1::MODEL_STATE_PENDING:
      state = static_cast<int64_t>(ModelState::kPending);
      break;
    case v1::MODEL_STATE_EXTRACTED:
      state = static_cast<int64_t>(ModelState::kExtracted);
      break;
    case v1::MODEL_STATE_FAILED:
      state = static_cast<int64_t>(ModelState::kFailed);
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("list models: unknown state ", static_cast<int>(request.state())));
  }
  absl::MutexLock lock(&mutex_);
  // Two statements rather than "?2 < 0 OR state = ?2", so that each walks
  // its index in order instead of sorting the collection.
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare(state < 0 ? "SELECT model_id, label, state, ordinal, attempts, error, "
                               "feature_count FROM models WHERE collection = ?1 AND ?2 < 0 AND "
                               "ordinal > ?3 ORDER BY ordinal LIMIT ?4"
                             : "SELECT model_id, label, state, ordinal, attempts, error, "
                               "feature_count FROM models WHERE collection = ?1 AND state = ?2 "
                               "AND ordinal > ?3 ORDER BY ordinal LIMIT ?4"));
  select.Bind(1, request.collection())
      .Bind(2, state)
      .Bind(3, after)
      .Bind(4, int64_t{page_size} + 1);
  v1::ListCollectionModelsResponse response;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) break;
    if (response.models_size() == static_cast<int>(page_size)) {
      response.set_next_page_token(absl::StrCat(response.models().rbegin()->ordinal()));
      break;
    }
    v1::ModelInfo* model = response.add_models();
    model->set_model_id(select.ColumnText(0));
    model->set_label(select.ColumnText(1));
    model->set_state(ToProto(static_cast<ModelState>(select.ColumnInt(2))));
    model->set_ordinal(select.ColumnInt(3));
    model->set_attempts(static_cast<uint32_t>(select.ColumnInt(4)));
    model->set_error(select.ColumnText(5));
    model->set_features(static_cast<uint32_t>(select.ColumnInt(6)));
  }
  return response;
}

}  // namespace meshseek
