// The index service's durable store: one SQLite row per (collection, model
// id) holding the model as it was added (ordinal, label, and its serialised
// histogram or global descriptor), schema in index_schema.h. Every add and
// remove is written here (WAL) before it is answered; the service loads the
// whole store into memory at start, so a kill -9 loses nothing acknowledged.
//
// Not thread-safe: the service serialises writers (index_service.h).
#ifndef MESHSEEK_SERVICES_INDEX_INDEX_STORE_H_
#define MESHSEEK_SERVICES_INDEX_INDEX_STORE_H_

#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/store/sqlite_db.h"
#include "meshseek/v1/index.pb.h"

namespace meshseek {

class IndexStore {
 public:
  /// Opens (creating, or migrating) `data_dir`/index.db.
  static absl::StatusOr<std::unique_ptr<IndexStore>> Open(const std::string& data_dir);

  /// Adds or replaces `model` in `collection`.
  absl::Status Upsert(const std::string& collection, const v1::IndexedModel& model);
  /// Removes the model if stored; OK either way.
  absl::Status Remove(const std::string& collection, const std::string& model_id);
  /// Every stored model. DataLoss naming the row for one that does not parse;
  /// `fn`'s error stops the walk and is returned.
  absl::Status ForEach(
      const std::function<absl::Status(const std::string& collection, const v1::IndexedModel&)>& fn);

 private:
  explicit IndexStore(std::unique_ptr<Database> db) : db_(std::move(db)) {}
  std::unique_ptr<Database> db_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_INDEX_INDEX_STORE_H_
