// The index service: per collection, each model's id, ordinal, label and
// bag-of-features histogram, ranked by exact symmetric KL divergence through
// an inverted file (common/search/kl_inverted_index.h): sparse storage, no
// copy of the collection per query, and queries in parallel with each other
// under a reader lock. A collection of a global method (LFD) holds each
// model's descriptor instead, ranked by the method's distance
// (common/search/global_descriptor_index.h); the first model added fixes the
// collection's kind.
//
// Every add and remove is written to SQLite (WAL) before it is answered, and
// the whole index is loaded into memory at start, so a kill -9 and restart
// lose no acknowledged model. Adds are upserts by (collection, model id): a
// retry never duplicates.
//
// One server may be one shard of a collection: the coordinator places each
// model on a shard and merges what the shards answer (Search's top-k, and
// ExportModels + Distances for the all-pairs matrix). A shard that holds no
// model of a collection answers NOT_FOUND like an unknown collection.
#ifndef MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_
#define MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "common/rpc/metrics.h"
#include "common/search/global_descriptor_index.h"
#include "common/search/kl_inverted_index.h"
#include "common/store/sqlite_db.h"
#include "meshseek/v1/index.grpc.pb.h"

namespace meshseek {

struct IndexServiceOptions {
  /// Folder of the database (index.db); created if missing.
  std::string data_dir;
  /// Threads for one search and for a batch of Distances (<= 0: all cores).
  /// Results do not depend on it.
  int num_threads = 0;

  absl::Status Validate() const;
};

class IndexService final : public v1::Index::Service {
 public:
  /// Most query histograms in one Distances request.
  static constexpr int kMaxDistanceQueries = 4096;
  /// Most model ids one Distances request may restrict itself to.
  static constexpr int kMaxDistanceModels = 65536;

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
  grpc::Status ExportModels(grpc::ServerContext* context,
                            const v1::ExportModelsRequest* request,
                            grpc::ServerWriter<v1::IndexedModel>* writer) override;
  grpc::Status Distances(grpc::ServerContext* context,
                         const v1::DistancesRequest* request,
                         v1::DistancesResponse* response) override;
  grpc::Status ListModels(grpc::ServerContext* context,
                          const v1::ListModelsRequest* request,
                          v1::ListModelsResponse* response) override;

  /// Bytes held by the in-memory index of every collection (for benchmarks).
  std::size_t MemoryBytes();

 private:
  struct Model {
    std::string model_id;
    uint64_t ordinal = 0;
    std::string label;
  };
  struct Collection {
    absl::flat_hash_map<std::string, uint32_t> docs;  // model id -> doc
    absl::flat_hash_map<uint32_t, Model> models;      // doc -> model
    uint32_t next_doc = 0;
    // Created by the first add, with its vocabulary and the default epsilon;
    // rebuilt when a request asks for another epsilon.
    std::optional<KlInvertedIndex> engine;
    // Instead of `engine`, for a collection of a global method.
    std::optional<GlobalDescriptorIndex> global;
  };
  // What one model is ranked by: a histogram, or a global descriptor.
  struct Signature {
    SparseHistogram histogram;
    std::optional<v1::GlobalDescriptor> descriptor;
  };
  // The signature of a request (AddModel, Search, a Distances query),
  // checked: InvalidArgument naming `what`.
  static absl::StatusOr<Signature> ParseSignature(const v1::SparseHistogram& histogram,
                                                  const v1::GlobalDescriptor* descriptor,
                                                  const std::string& what);
  // Why `signature` cannot join `collection` (another kind, vocabulary,
  // method or size), or OK. `model_id` may replace the only model.
  static absl::Status CheckFits(const Collection& collection,
                                const std::string& model_id,
                                const Signature& signature);

  IndexService(const IndexServiceOptions& options, std::unique_ptr<Database> db)
      : options_(options), db_(std::move(db)) {}
  absl::Status Load();
  // Puts one model into memory (after it is durable). Caller holds mutex_
  // for writing.
  absl::Status Place(Collection* collection,
                     const std::string& model_id,
                     uint64_t ordinal,
                     const std::string& label,
                     const Signature& signature) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  // Makes the engine of collection `name` use `epsilon` (0: the default),
  // rebuilding it under the writer lock when it uses another (collections keep
  // one epsilon, so this happens once, if ever).
  void UseEpsilon(const std::string& name, double epsilon) ABSL_LOCKS_EXCLUDED(mutex_);
  // The collection with an engine using `epsilon`; NotFound for an unknown or
  // empty one, Aborted if another epsilon was asked for meanwhile.
  absl::StatusOr<const Collection*> FindCollection(const std::string& name, double epsilon)
      ABSL_SHARED_LOCKS_REQUIRED(mutex_);
  // Docs in (ordinal, model id) order.
  static std::vector<uint32_t> DocsInOrder(const Collection& collection);
  // The docs of those of `model_ids` the collection holds, each once, in the
  // same order.
  static std::vector<uint32_t> DocsInOrder(const Collection& collection,
                                           const google::protobuf::RepeatedPtrField<std::string>& model_ids);
  // Sorts docs by (ordinal, model id).
  static void SortDocs(const Collection& collection, std::vector<uint32_t>* docs);

  const IndexServiceOptions options_;
  // Serialises writers: the database write and the in-memory update of one
  // add happen in the same order for every writer.
  absl::Mutex write_mutex_;
  std::unique_ptr<Database> db_ ABSL_GUARDED_BY(write_mutex_);
  // Readers (searches) share it; writers hold it only for the in-memory update.
  absl::Mutex mutex_;
  std::map<std::string, Collection> collections_ ABSL_GUARDED_BY(mutex_);
  // meshseek_index_models{collection}, read at scrape time. Last: unregistered
  // (waiting for a scrape in progress) before the collections go.
  std::unique_ptr<rpc::ScrapeGauge> models_gauge_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_
