// The coordinator: the API clients use (coordinator.proto). It owns
// collections (name, method and parameters, current codebook), their models
// (mesh, label, ingest order, state, stored local features) and jobs, in
// SQLite under its data folder, and orchestrates the stateless workers
// (resample, extract) and the stateful services (codebook, index). It never
// computes features or distances itself.
//
// Ingest: each model of a stream is validated, stored with state PENDING and
// only then acknowledged, so an acknowledged model survives kill -9. A fixed
// pool of `max_in_flight` dispatcher threads takes PENDING models from the
// database (no in-memory queue) and runs resample (RLD-SIFT) -> extract ->
// store features; when the collection already has a codebook, also encode ->
// index. Worker calls carry deadlines and are retried on transient failures;
// gRPC's round_robin spreads the retries over the healthy replicas, so a
// killed worker's models are redone elsewhere. A model that fails for a
// reason of its own (a degenerate mesh) is marked FAILED with the message.
// After a restart the dispatchers simply continue with what is PENDING.
// Acknowledgements wait while `max_pending` models wait (backpressure).
//
// Build: trains the codebook on every model's stored descriptors, in ingest
// order (the same input as the in-process pipeline), then encodes and indexes
// every model. The codebook id is derived from the job, and each model
// records the codebook it was indexed with, so a build interrupted by a
// restart resumes where it was.
#ifndef MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SERVICE_H_
#define MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SERVICE_H_

#include <atomic>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/rpc/client.h"
#include "common/store/sqlite_db.h"
#include "meshseek/v1/codebook.grpc.pb.h"
#include "meshseek/v1/coordinator.grpc.pb.h"
#include "meshseek/v1/extract.grpc.pb.h"
#include "meshseek/v1/index.grpc.pb.h"
#include "meshseek/v1/resample.grpc.pb.h"
#include "services/coordinator/index_shards.h"

namespace meshseek {

struct CoordinatorOptions {
  /// Folder of the database (coordinator.db); created if missing.
  std::string data_dir;
  /// gRPC targets of the services (see common/rpc/client.h): "host:port",
  /// "dns:///extract:50051", "ipv4:127.0.0.1:7001,127.0.0.1:7002".
  std::string resample_target;
  std::string extract_target;
  std::string codebook_target;
  /// One target per index shard, separated by commas (index_shards.h); the
  /// number of shards is fixed once the data folder has been used.
  std::string index_target;
  /// Models being resampled/extracted at once, over all workers (the
  /// dispatcher threads). Set it to about the total worker cores.
  int max_in_flight = 8;
  /// Ingest acknowledgements wait while this many models wait for extraction.
  int max_pending = 512;
  /// Deadline of one extraction or resampling call.
  absl::Duration extract_deadline = absl::Minutes(5);
  /// Deadline of every other call to a service.
  absl::Duration call_deadline = absl::Minutes(1);
  /// Tries of a call that fails transiently (worker gone, restarting,
  /// overloaded) before the coordinator gives up on that call for now; with
  /// the backoff (0.1 s doubling to 5 s) 12 tries span about 40 s.
  int call_attempts = 12;
  /// Largest message to and from the services.
  int max_message_bytes = 64 << 20;

  absl::Status Validate() const;
};

class CoordinatorService final : public v1::Coordinator::Service {
 public:
  static absl::StatusOr<std::unique_ptr<CoordinatorService>> Create(
      const CoordinatorOptions& options);
  ~CoordinatorService() override;

  /// Stops the dispatchers and build jobs (after the server has shut down).
  void Stop();

  grpc::Status CreateCollection(grpc::ServerContext* context,
                                const v1::CreateCollectionRequest* request,
                                v1::Collection* response) override;
  grpc::Status GetCollection(grpc::ServerContext* context,
                             const v1::GetCollectionRequest* request,
                             v1::Collection* response) override;
  grpc::Status Ingest(grpc::ServerContext* context,
                      grpc::ServerReaderWriter<v1::IngestAck, v1::IngestRequest>* stream) override;
  grpc::Status Build(grpc::ServerContext* context,
                     const v1::BuildRequest* request,
                     v1::JobStatus* response) override;
  grpc::Status GetJob(grpc::ServerContext* context,
                      const v1::JobRequest* request,
                      v1::JobStatus* response) override;
  grpc::Status WatchJob(grpc::ServerContext* context,
                        const v1::JobRequest* request,
                        grpc::ServerWriter<v1::JobStatus>* writer) override;
  grpc::Status Query(grpc::ServerContext* context,
                     const v1::QueryRequest* request,
                     v1::QueryResponse* response) override;
  grpc::Status RemoveModel(grpc::ServerContext* context,
                           const v1::RemoveModelFromCollectionRequest* request,
                           v1::RemoveModelFromCollectionResponse* response) override;
  grpc::Status Evaluate(grpc::ServerContext* context,
                        const v1::EvaluateRequest* request,
                        grpc::ServerWriter<v1::EvaluateRow>* writer) override;

 private:
  struct CollectionInfo {
    v1::PipelineParams params;
    RetrievalPipelineOptions options;
    std::string codebook_id;
  };
  struct ModelKey {
    std::string collection;
    std::string model_id;
    bool operator<(const ModelKey& o) const {
      return std::tie(collection, model_id) < std::tie(o.collection, o.model_id);
    }
  };

  explicit CoordinatorService(const CoordinatorOptions& options);
  absl::Status Open();
  void StartBackground();

  absl::StatusOr<CollectionInfo> FindCollection(const std::string& name);
  absl::StatusOr<v1::JobStatus> JobStatusOf(const std::string& job_id);
  absl::StatusOr<std::string> NewJob(const std::string& kind,
                                     const std::string& collection,
                                     uint64_t total);
  absl::Status FinishJob(const std::string& job_id, v1::JobState state, const std::string& message);

  // Ingest of one model: validates, stores, returns the ack.
  absl::StatusOr<v1::IngestAck> AcceptModel(const v1::IngestRequest& request,
                                            const std::string& job_id);

  // Dispatcher loop and one model's work.
  void DispatchLoop();
  bool ClaimPending(ModelKey* key);
  absl::Status ProcessModel(const ModelKey& key);
  // Resample (RLD-SIFT) and extract one mesh on the workers.
  absl::StatusOr<v1::LocalFeatures> ExtractOnWorkers(const v1::Mesh& mesh,
                                                     const CollectionInfo& info,
                                                     const std::string& model_id);
  absl::StatusOr<v1::SparseHistogram> EncodeOnCodebook(const std::string& codebook_id,
                                                       const v1::LocalFeatures& features);
  absl::Status AddToIndex(const std::string& collection,
                          const std::string& model_id,
                          uint64_t ordinal,
                          const std::string& label,
                          const v1::SparseHistogram& histogram);

  // Build job body; resumable.
  void RunBuild(const std::string& job_id, const std::string& collection);

  const CoordinatorOptions options_;
  // Retries of every call to a service (options_.call_attempts tries).
  rpc::RetryOptions retry_;
  std::unique_ptr<v1::Resample::Stub> resample_;
  std::unique_ptr<v1::Extract::Stub> extract_;
  std::unique_ptr<v1::Codebook::Stub> codebook_;
  std::unique_ptr<IndexShards> index_;

  absl::Mutex mutex_;
  std::unique_ptr<Database> db_ ABSL_GUARDED_BY(mutex_);
  std::set<ModelKey> in_flight_ ABSL_GUARDED_BY(mutex_);
  // Models that failed transiently: not retried before this time.
  std::map<ModelKey, absl::Time> retry_after_ ABSL_GUARDED_BY(mutex_);
  int64_t pending_ ABSL_GUARDED_BY(mutex_) = 0;
  // Signalled when models become pending (dispatchers) or stop being pending
  // (ingest streams waiting under backpressure).
  absl::CondVar work_changed_;
  // Collections with a build running (one at a time per collection).
  std::set<std::string> building_ ABSL_GUARDED_BY(mutex_);
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SERVICE_H_
