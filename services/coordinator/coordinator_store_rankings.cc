// CoordinatorStore: the ranking states of fused and re-ranked collections and
// the models that joined them live (coordinator_store.h).
#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "services/coordinator/coordinator_store.h"

namespace meshseek {

absl::Status CoordinatorStore::SetRanking(const std::string& collection,
                                          const std::string& build,
                                          const std::string& state) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Transaction transaction, Transaction::Begin(db_.get()));
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement upsert,
      db_->Prepare("INSERT INTO rankings (collection, build, state) VALUES (?, ?, ?) "
                   "ON CONFLICT (collection) DO UPDATE SET build = excluded.build, "
                   "state = excluded.state"));
  MESHSEEK_RETURN_IF_ERROR(upsert.Bind(1, collection).Bind(2, build).BindBlob(3, state).Run());
  MESHSEEK_ASSIGN_OR_RETURN(Statement erase,
                            db_->Prepare("DELETE FROM ranking_joins WHERE collection = ?"));
  MESHSEEK_RETURN_IF_ERROR(erase.Bind(1, collection).Run());
  return transaction.Commit();
}

absl::StatusOr<std::optional<StoredRanking>> CoordinatorStore::GetRanking(
    const std::string& collection) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(Statement select,
                            db_->Prepare("SELECT build, state FROM rankings WHERE collection = ?"));
  select.Bind(1, collection);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (!found) return std::nullopt;
  return StoredRanking{select.ColumnText(0), select.ColumnBlob(1)};
}

absl::StatusOr<bool> CoordinatorStore::AddRankingJoin(const std::string& collection,
                                                      const std::string& build,
                                                      const std::string& model_id,
                                                      const std::string& join) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement insert,
      db_->Prepare("INSERT INTO ranking_joins (collection, seq, build, model_id, node) "
                   "SELECT ?1, (SELECT COALESCE(MAX(seq), -1) + 1 FROM ranking_joins WHERE "
                   "collection = ?1), ?2, ?3, ?4 WHERE EXISTS (SELECT 1 FROM rankings WHERE "
                   "collection = ?1 AND build = ?2) RETURNING seq"));
  insert.Bind(1, collection).Bind(2, build).Bind(3, model_id).BindBlob(4, join);
  MESHSEEK_ASSIGN_OR_RETURN(const bool stored, insert.Step());
  if (stored) insert.Reset();
  return stored;
}

absl::StatusOr<std::vector<std::string>> CoordinatorStore::RankingJoins(
    const std::string& collection, const std::string& build) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare(
          "SELECT node FROM ranking_joins WHERE collection = ? AND build = ? ORDER BY seq"));
  select.Bind(1, collection).Bind(2, build);
  std::vector<std::string> joins;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) return joins;
    joins.push_back(select.ColumnBlob(0));
  }
}

absl::StatusOr<std::vector<RankedModel>> CoordinatorStore::IndexedModels(
    const std::vector<std::string>& collections, const std::string& build) {
  absl::MutexLock lock(&mutex_);
  std::string in;
  for (std::size_t i = 0; i < collections.size(); ++i) absl::StrAppend(&in, ", ?", i + 3);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare(absl::StrCat(
          "SELECT model_id, MIN(ordinal) AS first, MIN(label) FROM models WHERE collection IN (",
          in.substr(2),
          ") AND state = 1 AND indexed_codebook = collection || '@' || ?1 GROUP BY model_id "
          "HAVING COUNT(*) = ?2 ORDER BY first, model_id")));
  select.Bind(1, build).Bind(2, static_cast<int64_t>(collections.size()));
  for (std::size_t i = 0; i < collections.size(); ++i) {
    select.Bind(static_cast<int>(i) + 3, collections[i]);
  }
  std::vector<RankedModel> models;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) return models;
    models.push_back(
        {select.ColumnText(0), static_cast<uint64_t>(select.ColumnInt(1)), select.ColumnText(2)});
  }
}

}  // namespace meshseek
