// CoordinatorStore: the models (coordinator_store.h).
#include <algorithm>
#include <limits>
#include <optional>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "common/base/logging.h"
#include "common/base/status_macros.h"
#include "services/coordinator/coordinator_schema.h"
#include "services/coordinator/coordinator_store.h"

namespace meshseek {
namespace {

constexpr uint32_t kDefaultPageSize = 100;
constexpr uint32_t kMaxPageSize = 1000;

int64_t ToMicros(absl::Time t) { return absl::ToUnixMicros(t); }

}  // namespace

// --------------------------------------------------------------------- models

absl::StatusOr<CoordinatorStore::AddedModel> CoordinatorStore::AddModel(
    const std::vector<std::string>& collections,
    const std::string& model_id,
    const std::string& label,
    const std::string& mesh,
    const std::string& job_id,
    const ModelThumbnail& thumbnail) {
  const std::string fingerprint = MeshFingerprint(mesh);
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  std::optional<AddedModel> result;
  for (const std::string& collection : collections) {
    // The mesh once: in the first collection's row (a fused collection's
    // first member); the others find it there (MeshInRows).
    const std::string& stored_mesh = &collection == &collections.front() ? mesh : std::string();
    MESHSEEK_ASSIGN_OR_RETURN(Statement existing,
                              db_->Prepare("SELECT fingerprint, label, job_id FROM models "
                                           "WHERE collection = ? AND model_id = ?"));
    existing.Bind(1, collection).Bind(2, model_id);
    MESHSEEK_ASSIGN_OR_RETURN(const bool found, existing.Step());
    if (found) {
      if (existing.ColumnText(0) != fingerprint || existing.ColumnText(1) != label) {
        return absl::AlreadyExistsError(
            absl::StrCat("model ",
                         model_id,
                         " exists in collection '",
                         collection,
                         "' with another mesh or label; remove it first"));
      }
      if (!result.has_value()) result = AddedModel{false, existing.ColumnText(2), 0};
      continue;
    }
    existing.Reset();
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement insert,
        db_->Prepare("INSERT INTO models (collection, model_id, ordinal, label, mesh, "
                     "fingerprint, state, job_id) VALUES (?1, ?2, (SELECT COALESCE(MAX(ordinal), "
                     "-1) + 1 FROM models WHERE collection = ?1), ?3, ?4, ?5, 0, ?6)"));
    MESHSEEK_RETURN_IF_ERROR(insert.Bind(1, collection)
                                 .Bind(2, model_id)
                                 .Bind(3, label)
                                 .BindBlob(4, stored_mesh)
                                 .Bind(5, fingerprint)
                                 .Bind(6, job_id)
                                 .Run());
    const int rows = result.has_value() ? result->rows : 0;
    result = AddedModel{true, job_id, rows + 1};
  }
  if (!thumbnail.png.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(Statement insert,
                              db_->Prepare("INSERT OR IGNORE INTO thumbnails (collection, "
                                           "model_id, png) VALUES (?, ?, ?)"));
    MESHSEEK_RETURN_IF_ERROR(
        insert.Bind(1, thumbnail.collection).Bind(2, model_id).BindBlob(3, thumbnail.png).Run());
  }
  MESHSEEK_RETURN_IF_ERROR(transaction.Commit());
  return result.value_or(AddedModel{false, job_id, 0});
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
      Statement select,
      db_->Prepare("SELECT mesh, ordinal, label, attempts, job_id FROM models "
                   "WHERE collection = ? AND model_id = ? AND state = 0"));
  select.Bind(1, key.collection).Bind(2, key.model_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (!found) return std::nullopt;
  PendingModel model;
  model.mesh = select.ColumnBlob(0);
  if (model.mesh.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(std::optional<std::string> mesh, MeshInRows(key));
    model.mesh = std::move(mesh).value_or("");
  }
  model.ordinal = static_cast<uint64_t>(select.ColumnInt(1));
  model.label = select.ColumnText(2);
  model.attempts = static_cast<int>(select.ColumnInt(3));
  model.job_id = select.ColumnText(4);
  return model;
}

absl::StatusOr<std::vector<CoordinatorStore::StateCount>> CoordinatorStore::CountModelsByState() {
  absl::MutexLock lock(&mutex_);
  // Walks models_by_state_in_order (collection, state, ...) without a table read.
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT collection, state, COUNT(*) FROM models GROUP BY collection, state"));
  std::vector<StateCount> counts;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) break;
    counts.push_back({select.ColumnText(0),
                      static_cast<ModelState>(select.ColumnInt(1)),
                      static_cast<uint64_t>(select.ColumnInt(2))});
  }
  return counts;
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
  return EndPending(key, ModelState::kExtracted, -1, "", &features, feature_count);
}

absl::StatusOr<bool> CoordinatorStore::MarkFailed(const ModelKey& key,
                                                  int attempts,
                                                  const std::string& reason) {
  return EndPending(key, ModelState::kFailed, attempts, reason, nullptr, 0);
}

absl::StatusOr<bool> CoordinatorStore::EndPending(const ModelKey& key,
                                                  ModelState state,
                                                  int attempts,
                                                  const std::string& error,
                                                  const std::string* features,
                                                  uint32_t feature_count) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement update,
      db_->Prepare("UPDATE models SET state = ?, error = ?, feature_count = ?, "
                   "attempts = CASE WHEN ? < 0 THEN attempts + 1 ELSE ? END, retry_at = 0 "
                   "WHERE collection = ? AND model_id = ? AND state = 0 RETURNING job_id"));
  update.Bind(1, static_cast<int64_t>(state))
      .Bind(2, error)
      .Bind(3, int64_t{feature_count})
      .Bind(4, int64_t{attempts})
      .Bind(5, int64_t{attempts})
      .Bind(6, key.collection)
      .Bind(7, key.model_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool changed, update.Step());
  if (!changed) return false;
  const std::string job_id = update.ColumnText(0);
  update.Reset();
  MESHSEEK_RETURN_IF_ERROR(FinishIngestJobIfDone(job_id));
  MESHSEEK_RETURN_IF_ERROR(transaction.Commit());
  // The features after the row, under the lock: only the extraction that
  // ended the model writes them (never a late one of a mesh removed and
  // ingested again), and a removal waits for it. A kill between the two, or
  // a write that fails, leaves an extracted model without features: the
  // build extracts it again, as it does for freed ones.
  if (features != nullptr) {
    if (absl::Status put = features_.Put(key.collection, key.model_id, *features); !put.ok()) {
      features_.Remove(key.collection, key.model_id);
      MESHSEEK_LOG(WARNING) << "coordinator: model " << key.model_id << " of " << key.collection
                            << ": features not kept (the build extracts them again): " << put;
    }
  }
  return true;
}

absl::Status CoordinatorStore::ScheduleRetry(const ModelKey& key,
                                             int attempts,
                                             absl::Time retry_at,
                                             const std::string& error) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Statement update,
                            db_->Prepare("UPDATE models SET attempts = ?, retry_at = ?, error = ? "
                                         "WHERE collection = ? AND model_id = ? AND state = 0"));
  return update.Bind(1, int64_t{attempts})
      .Bind(2, ToMicros(retry_at))
      .Bind(3, error)
      .Bind(4, key.collection)
      .Bind(5, key.model_id)
      .Run();
}

absl::Status CoordinatorStore::MarkIndexed(const ModelKey& key,
                                           const std::string& codebook_id,
                                           bool live) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement mark,
      db_->Prepare("UPDATE models SET indexed_codebook = ?, live = ? WHERE collection = ? "
                   "AND model_id = ?"));
  return mark.Bind(1, codebook_id)
      .Bind(2, int64_t{live ? 1 : 0})
      .Bind(3, key.collection)
      .Bind(4, key.model_id)
      .Run();
}

absl::StatusOr<std::optional<ModelState>> CoordinatorStore::RemoveModel(const ModelKey& key) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  MESHSEEK_ASSIGN_OR_RETURN(Statement erase,
                            db_->Prepare("DELETE FROM models WHERE collection = ? AND model_id = ? "
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
  features_.Remove(key.collection, key.model_id);
  return state;
}

namespace {

constexpr const char* kSelectExtracted =
    "SELECT model_id, ordinal, label, indexed_codebook FROM models "
    "WHERE collection = ?1 AND state = 1";

ExtractedModel ExtractedRow(const Statement& select) {
  return {select.ColumnText(0), static_cast<uint64_t>(select.ColumnInt(1)), select.ColumnText(2),
          select.ColumnText(3)};
}

}  // namespace

absl::StatusOr<std::vector<ExtractedModel>> CoordinatorStore::ExtractedModels(
    const std::string& collection, const std::optional<std::string>& not_indexed_with) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare(absl::StrCat(kSelectExtracted,
                                not_indexed_with.has_value() ? " AND indexed_codebook != ?2" : "",
                                " ORDER BY ordinal")));
  select.Bind(1, collection);
  if (not_indexed_with.has_value()) select.Bind(2, *not_indexed_with);
  std::vector<ExtractedModel> models;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) return models;
    models.push_back(ExtractedRow(select));
  }
}

absl::Status CoordinatorStore::DropFeatures(const std::vector<std::string>& collections,
                                           const std::string& build,
                                           const std::string& model_id) {
  std::vector<ModelKey> indexed;
  {
    absl::MutexLock lock(&mutex_);
    std::string in;
    for (std::size_t i = 0; i < collections.size(); ++i) absl::StrAppend(&in, ", ?", i + 3);
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement select,
        db_->Prepare(absl::StrCat("SELECT collection, model_id FROM models WHERE collection IN (",
                                  in.substr(2),
                                  ") AND state = 1 AND indexed_codebook = collection || '@' || ?1 "
                                  "AND (?2 = '' OR model_id = ?2)")));
    select.Bind(1, build).Bind(2, model_id);
    for (std::size_t i = 0; i < collections.size(); ++i) {
      select.Bind(static_cast<int>(i) + 3, collections[i]);
    }
    while (true) {
      MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
      if (!row) break;
      indexed.push_back({select.ColumnText(0), select.ColumnText(1)});
    }
  }
  for (const ModelKey& key : indexed) features_.Remove(key.collection, key.model_id);
  return absl::OkStatus();
}

std::optional<std::string> CoordinatorStore::LoadFeatures(const ModelKey& key) const {
  return features_.Get(key.collection, key.model_id);
}

absl::StatusOr<std::optional<ExtractedModel>> CoordinatorStore::LoadExtracted(
    const ModelKey& key) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Statement select,
                            db_->Prepare(absl::StrCat(kSelectExtracted, " AND model_id = ?2")));
  select.Bind(1, key.collection).Bind(2, key.model_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (!found) return std::nullopt;
  return ExtractedRow(select);
}

namespace {

// The state a listing keeps (-1: every state).
absl::StatusOr<int64_t> StateFilter(v1::ModelState state) {
  switch (state) {
    case v1::MODEL_STATE_UNSPECIFIED:
      return -1;
    case v1::MODEL_STATE_PENDING:
      return static_cast<int64_t>(ModelState::kPending);
    case v1::MODEL_STATE_EXTRACTED:
      return static_cast<int64_t>(ModelState::kExtracted);
    case v1::MODEL_STATE_FAILED:
      return static_cast<int64_t>(ModelState::kFailed);
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("list models: unknown state ", static_cast<int>(state)));
  }
}

// The listing's statement: ?1 collection, ?2 state (-1: any), ?3 the last
// ordinal of the page before, ?4 rows; the members of a fused collection
// follow as ?5...
std::string ListModelsSql(std::size_t members, int64_t state) {
  if (members > 0) {
    // Each model once over the members, in the state CountModels gives it.
    std::string in;
    for (std::size_t i = 0; i < members; ++i) absl::StrAppend(&in, i ? ", ?" : "?", i + 5);
    return absl::StrCat(
        "SELECT model_id, MIN(label), CASE WHEN MAX(state = 2) THEN 2 WHEN MAX(state = 0) THEN 0 "
        "ELSE 1 END AS merged, MIN(ordinal) AS first, MAX(attempts), GROUP_CONCAT(CASE WHEN "
        "error != '' THEN substr(collection, instr(collection, '~') + 1) || ': ' || error END, "
        "'; '), SUM(feature_count) FROM models WHERE collection IN (",
        in,
        ") GROUP BY model_id "
        "HAVING (?2 < 0 OR merged = ?2) AND first > ?3 ORDER BY first LIMIT ?4");
  }
  // Two statements rather than "?2 < 0 OR state = ?2", so that each walks its
  // index in order instead of sorting the collection.
  return state < 0 ? "SELECT model_id, label, state, ordinal, attempts, error, feature_count "
                     "FROM models WHERE collection = ?1 AND ?2 < 0 AND ordinal > ?3 "
                     "ORDER BY ordinal LIMIT ?4"
                   : "SELECT model_id, label, state, ordinal, attempts, error, feature_count "
                     "FROM models WHERE collection = ?1 AND state = ?2 AND ordinal > ?3 "
                     "ORDER BY ordinal LIMIT ?4";
}

}  // namespace

absl::StatusOr<v1::ListCollectionModelsResponse> CoordinatorStore::ListModels(
    const v1::ListCollectionModelsRequest& request, const std::vector<std::string>& members) {
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
  MESHSEEK_ASSIGN_OR_RETURN(const int64_t state, StateFilter(request.state()));
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Statement select, db_->Prepare(ListModelsSql(members.size(), state)));
  select.Bind(1, request.collection())
      .Bind(2, state)
      .Bind(3, after)
      .Bind(4, int64_t{page_size} + 1);
  // Numbered parameters ?1..?4 come first; the members follow as ?5...
  for (std::size_t i = 0; i < members.size(); ++i) {
    select.Bind(static_cast<int>(i) + 5, members[i]);
  }
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
