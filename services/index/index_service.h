// The index service: per collection, each model's id, ordinal, label and
// bag-of-features histogram, ranked by exact symmetric KL divergence through
// an inverted file (common/search/kl_inverted_index.h): sparse storage, no
// copy of the collection per query, and queries in parallel with each other
// under a reader lock. A collection of a global method (LFD) holds each
// model's descriptor instead, ranked by the method's distance
// (common/search/global_descriptor_index.h); the first model added fixes the
// collection's kind.
//
// Every add and remove is written to SQLite (WAL, index_store.h) before it is
// answered, and the whole index is loaded from it at start
// (index_collection.h), so a kill -9 and restart lose no acknowledged model.
// The histograms' forward indexes live in unlinked files under
// <data_dir>/forward (kl_inverted_index.h, "Storage"), rebuilt by that load:
// derived data that a crash cannot leave half-written.
// Adds are upserts by (collection, model id): a retry never duplicates.
//
// One server may be one shard of a collection: the coordinator places each
// model on a shard and merges what the shards answer (Search's top-k, and
// ExportModels + Distances for the all-pairs matrix). A shard that holds no
// model of a collection answers NOT_FOUND like an unknown collection.
#ifndef MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_
#define MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_

#include <map>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "common/rpc/handler.h"
#include "common/rpc/metrics.h"
#include "meshseek/v1/index.pb.h"
#include "services/index/index_collection.h"
#include "services/index/index_store.h"

namespace meshseek {

struct IndexServiceOptions {
  /// Folder of the database (index.db); created if missing.
  std::string data_dir;
  /// Threads for one search and for a batch of Distances (<= 0: all cores).
  /// Results do not depend on it.
  int num_threads = 0;
  /// A collection's postings are freed past this many models on this
  /// server, and its full scans read the forward index (kl_inverted_index.h,
  /// "Storage"): at 20,000 BF-DSIFT models the postings take about 0.8 GB,
  /// and every exact graph (up to the coordinator's 5,000 models) and every
  /// development set is far below. At least 1.
  std::size_t postings_max_models = 20000;

  absl::Status Validate() const;
};

class IndexService final {
 public:
  /// Most query histograms in one Distances request.
  static constexpr int kMaxDistanceQueries = 4096;
  /// Most model ids one Distances request may restrict itself to (also the
  /// most candidates of a Neighbors request).
  static constexpr int kMaxDistanceModels = 65536;
  /// Most neighbours a Neighbors query may ask for.
  static constexpr uint32_t kMaxNeighbors = 1024;
  /// Most model ids in all the rows of one PairDistances request.
  static constexpr std::size_t kMaxPairIds = 1 << 20;
  /// Lists a Neighbors stream computes under one lock and sends in one
  /// message: about 4 MB of message at 50 neighbours.
  static constexpr std::size_t kNeighborBatch = 256;

  static absl::StatusOr<std::unique_ptr<IndexService>> Create(const IndexServiceOptions& options);

  absl::StatusOr<v1::AddModelResponse> AddModel(const v1::AddModelRequest& request,
                                                const rpc::CallContext& call);
  absl::StatusOr<v1::RemoveModelResponse> RemoveModel(const v1::RemoveModelRequest& request,
                                                      const rpc::CallContext& call);
  absl::StatusOr<v1::SearchResponse> Search(const v1::SearchRequest& request,
                                            const rpc::CallContext& call);
  absl::Status ExportModels(const v1::ExportModelsRequest& request,
                            rpc::Writer<v1::IndexedModel> write,
                            const rpc::CallContext& call);
  absl::StatusOr<v1::DistancesResponse> Distances(const v1::DistancesRequest& request,
                                                  const rpc::CallContext& call);
  absl::StatusOr<v1::ListModelsResponse> ListModels(const v1::ListModelsRequest& request,
                                                    const rpc::CallContext& call);
  absl::Status Neighbors(const v1::NeighborsRequest& request,
                         rpc::Writer<v1::NeighborLists> write,
                         const rpc::CallContext& call);
  absl::StatusOr<v1::PairDistancesResponse> PairDistances(const v1::PairDistancesRequest& request,
                                                          const rpc::CallContext& call);

  /// Bytes held by the in-memory index of every collection (for benchmarks).
  std::size_t MemoryBytes();

 private:
  IndexService(const IndexServiceOptions& options, std::unique_ptr<IndexStore> store)
      : options_(options), store_(std::move(store)) {
    storage_.forward_dir = options.data_dir + "/forward";
    storage_.postings_max_models = options.postings_max_models;
  }
  // The collection `name`, made empty (with storage_) if new.
  IndexCollection& CollectionNamed(const std::string& name) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  absl::Status Load();
  // Makes collection `name` rank with `epsilon` (0: the default), rebuilding
  // its inverted file under the writer lock when it uses another.
  absl::Status UseEpsilon(const std::string& name, double epsilon) ABSL_LOCKS_EXCLUDED(mutex_);
  // The collection, ranking with `epsilon` (0: the default); NotFound for an
  // unknown or empty one, Aborted if another epsilon was asked for meanwhile.
  absl::StatusOr<const IndexCollection*> FindCollection(const std::string& name, double epsilon)
      ABSL_SHARED_LOCKS_REQUIRED(mutex_);
  // The collection whatever it is ranked with (a search by picture, which
  // has no epsilon); NotFound as above.
  absl::StatusOr<const IndexCollection*> FindCollection(const std::string& name)
      ABSL_SHARED_LOCKS_REQUIRED(mutex_);

  const IndexServiceOptions options_;
  KlIndexStorage storage_;
  // Serialises writers: the store's write and the in-memory update of one
  // add happen in the same order for every writer.
  absl::Mutex write_mutex_;
  std::unique_ptr<IndexStore> store_ ABSL_GUARDED_BY(write_mutex_);
  // Readers (searches) share it; writers hold it only for the in-memory update.
  absl::Mutex mutex_;
  std::map<std::string, IndexCollection> collections_ ABSL_GUARDED_BY(mutex_);
  // meshseek_index_models{collection}, read at scrape time. Last: unregistered
  // (waiting for a scrape in progress) before the collections go.
  std::unique_ptr<rpc::ScrapeGauge> models_gauge_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_INDEX_INDEX_SERVICE_H_
