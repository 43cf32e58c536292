// The index service: per collection, each model's id, ordinal, label and
// bag-of-features histogram, ranked by symmetric KL divergence
// (QueryDistances / RankCollection, the in-process pipeline's code).
//
// Every add and remove is written to SQLite (WAL) before it is answered, and
// the whole index is loaded into memory at start, so a kill -9 and restart
// lose no acknowledged model. Adds are upserts by (collection, model id): a
// retry never duplicates.
#ifndef MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_
#define MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "common/store/sqlite_db.h"
#include "meshseek/v1/index.grpc.pb.h"

namespace meshseek {

struct IndexServiceOptions {
  /// Folder of the database (index.db); created if missing.
  std::string data_dir;
  /// Threads for ranking (<= 0: all cores). Results do not depend on it.
  int num_threads = 0;

  absl::Status Validate() const;
};

class IndexService final : public v1::Index::Service {
 public:
  static absl::StatusOr<std::unique_ptr<IndexService>> Create(const IndexServiceOptions& options);

  grpc::Status AddModel(grpc::ServerContext* context,
                        const v1::AddModelRequest* request,
                        v1::AddModelResponse* response) override;
  grpc::Status RemoveModel(grpc::ServerContext* context,
                           const v1::RemoveModelRequest* request,
                           v1::RemoveModelResponse* response) override;
  grpc::Status Search(grpc::ServerContext* context,
                      const v1::SearchRequest* request,
                      v1::SearchResponse* response) override;
  grpc::Status DistanceMatrix(grpc::ServerContext* context,
                              const v1::DistanceMatrixRequest* request,
                              grpc::ServerWriter<v1::DistanceRow>* writer) override;
  grpc::Status ListModels(grpc::ServerContext* context,
                          const v1::ListModelsRequest* request,
                          v1::ListModelsResponse* response) override;

 private:
  struct Entry {
    std::string model_id;
    uint64_t ordinal = 0;
    std::string label;
    std::vector<float> histogram;  // dense; empty = no features
    uint32_t vocabulary = 0;
  };
  IndexService(const IndexServiceOptions& options, std::unique_ptr<Database> db)
      : options_(options), db_(std::move(db)) {}
  absl::Status Load();
  // The collection's entries in ordinal order (ties by id), or NotFound.
  absl::StatusOr<std::vector<Entry>> Snapshot(const std::string& collection);

  const IndexServiceOptions options_;
  absl::Mutex mutex_;
  std::unique_ptr<Database> db_ ABSL_GUARDED_BY(mutex_);
  // collection -> model id -> entry.
  std::map<std::string, std::map<std::string, Entry>> collections_ ABSL_GUARDED_BY(mutex_);
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_
