#include "services/index/index_store.h"

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "services/index/index_schema.h"

namespace meshseek {

absl::StatusOr<std::unique_ptr<IndexStore>> IndexStore::Open(const std::string& data_dir) {
  std::error_code error;
  std::filesystem::create_directories(data_dir, error);
  MESHSEEK_ASSIGN_OR_RETURN(std::unique_ptr<Database> db, Database::Open(data_dir + "/index.db"));
  MESHSEEK_RETURN_IF_ERROR(MigrateIndexSchema(db.get()));
  return std::unique_ptr<IndexStore>(new IndexStore(std::move(db)));
}

absl::Status IndexStore::Upsert(const std::string& collection, const v1::IndexedModel& model) {
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement upsert,
      db_->Prepare("INSERT OR REPLACE INTO models (collection, model_id, ordinal, label, "
                   "histogram, descriptor) VALUES (?, ?, ?, ?, ?, ?)"));
  return upsert.Bind(1, collection)
      .Bind(2, model.model_id())
      .Bind(3, static_cast<int64_t>(model.ordinal()))
      .Bind(4, model.label())
      .BindBlob(5, model.histogram().SerializeAsString())
      .BindBlob(6, model.has_global_descriptor() ? model.global_descriptor().SerializeAsString()
                                                 : std::string())
      .Run();
}

absl::Status IndexStore::Remove(const std::string& collection, const std::string& model_id) {
  MESHSEEK_ASSIGN_OR_RETURN(Statement remove,
                            db_->Prepare("DELETE FROM models WHERE collection = ? AND model_id = ?"));
  return remove.Bind(1, collection).Bind(2, model_id).Run();
}

absl::Status IndexStore::ForEach(
    const std::function<absl::Status(const std::string&, const v1::IndexedModel&)>& fn) {
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare(
          "SELECT collection, model_id, ordinal, label, histogram, descriptor FROM models"));
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) return absl::OkStatus();
    const std::string collection = select.ColumnText(0);
    v1::IndexedModel model;
    model.set_model_id(select.ColumnText(1));
    model.set_ordinal(static_cast<uint64_t>(select.ColumnInt(2)));
    model.set_label(select.ColumnText(3));
    const std::string descriptor = select.ColumnBlob(5);
    // A model holds one of the two (an empty histogram column is a model
    // without features, not an absent one).
    const bool parsed = descriptor.empty()
                            ? model.mutable_histogram()->ParseFromString(select.ColumnBlob(4))
                            : model.mutable_global_descriptor()->ParseFromString(descriptor);
    if (!parsed) {
      return absl::DataLossError(absl::StrCat("index: stored histogram of model '", model.model_id(),
                                              "' in collection '", collection,
                                              "': does not parse"));
    }
    MESHSEEK_RETURN_IF_ERROR(fn(collection, model));
  }
}

}  // namespace meshseek
