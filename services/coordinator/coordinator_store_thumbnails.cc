// CoordinatorStore: thumbnails, stored meshes and the list of collections
// (coordinator_store.h).
#include "common/base/status_macros.h"
#include "services/coordinator/coordinator_store.h"

namespace meshseek {

absl::StatusOr<std::optional<std::string>> CoordinatorStore::ModelMesh(const ModelKey& key) {
  absl::MutexLock lock(&mutex_);
  return MeshInRows(key);
}

absl::StatusOr<std::optional<std::string>> CoordinatorStore::MeshInRows(const ModelKey& key) {
  // The row itself, or for a fused collection's member its sibling members'
  // rows: names "<fused>~<method>" sort in ["<fused>~", "<fused>~~") as
  // methods are lower-case letters.
  const std::size_t tilde = key.collection.find('~');
  const std::string fused =
      tilde == std::string::npos ? key.collection : key.collection.substr(0, tilde);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT mesh FROM models WHERE model_id = ?2 AND (collection = ?1 OR "
                   "(?3 AND collection > ?4 || '~' AND collection < ?4 || '~~')) "
                   "ORDER BY length(mesh) = 0 LIMIT 1"));
  select.Bind(1, key.collection)
      .Bind(2, key.model_id)
      .Bind(3, int64_t{tilde != std::string::npos})
      .Bind(4, fused);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (!found) return std::nullopt;
  return select.ColumnBlob(0);
}

absl::StatusOr<std::optional<std::string>> CoordinatorStore::GetThumbnail(const ModelKey& key) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT png FROM thumbnails WHERE collection = ? AND model_id = ?"));
  select.Bind(1, key.collection).Bind(2, key.model_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (!found) return std::nullopt;
  return select.ColumnBlob(0);
}

absl::Status CoordinatorStore::SetThumbnail(const ModelKey& key, const std::string& png) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement insert,
      db_->Prepare(
          "INSERT OR REPLACE INTO thumbnails (collection, model_id, png) VALUES (?, ?, ?)"));
  return insert.Bind(1, key.collection).Bind(2, key.model_id).BindBlob(3, png).Run();
}

absl::Status CoordinatorStore::RemoveThumbnail(const ModelKey& key) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement erase,
      db_->Prepare("DELETE FROM thumbnails WHERE collection = ? AND model_id = ?"));
  return erase.Bind(1, key.collection).Bind(2, key.model_id).Run();
}

absl::StatusOr<std::vector<std::string>> CoordinatorStore::ListCollectionNames() {
  absl::MutexLock lock(&mutex_);
  // Members are "<name>~<method>"; names clients give cannot hold '~'.
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT name FROM collections WHERE instr(name, '~') = 0 ORDER BY name"));
  std::vector<std::string> names;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) return names;
    names.push_back(select.ColumnText(0));
  }
}

}  // namespace meshseek
