// The coordinator: the API clients use (coordinator.proto). It owns
// collections (name, method and parameters, current codebook), their models
// (mesh, label, ingest order, state, stored local features) and jobs, and
// orchestrates the stateless workers (resample, extract) and the stateful
// services (codebook, index). It never computes features or distances itself.
//
// Its parts, in dependency order:
//   coordinator_options  the options and their validation;
//   coordinator_schema   the database schema, its versions and migrations;
//   coordinator_store    all durable state (SQLite): every SQL statement;
//   index_shards         the index as one or more shards;
//   workers              clients of the other services, deadlines, retries;
//   dispatcher           PENDING models -> extract -> store (-> live index);
//   ranking              fused and re-ranked collections: the state a build
//                        leaves, queries and rows ranked with it;
//   live_index           models extracted into a built collection: indexed
//                        and joined to its ranking state without a build;
//   build_runner         build jobs: train, encode, index; resumable;
//   coordinator_service  the RPC handlers (this file): validate, delegate;
//                        coordinator_query.cc holds Query and Evaluate.
//
// A fused collection ("bfdsift+rld+lsf+lfd") is a collection of its own
// parameters whose models live in one member collection per method
// ("<name>~<method>", workers.h): ingest stores each model in every member,
// the dispatchers extract each member's copy with its method, a build
// builds every member and then the ranking state; queries and evaluation go
// through the fused collection only.
//
// Thumbnails: each model's picture is rendered when it is ingested and
// stored with it (in the same transaction); a model stored before there
// were thumbnails gets its picture drawn from its stored mesh on first ask.
//
// Ingest: each model of a stream is validated, stored PENDING and only then
// acknowledged, so an acknowledged model survives kill -9; acknowledgements
// wait while `max_pending` models wait (backpressure). A model that cannot be
// extracted ends FAILED with its reason (dispatcher.h); ListModels and
// `meshseek status` show it, and builds go on without it.
#ifndef MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SERVICE_H_
#define MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SERVICE_H_

#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "common/rpc/handler.h"
#include "common/rpc/metrics.h"
#include "meshseek/v1/coordinator.pb.h"
#include "services/coordinator/build_runner.h"
#include "services/coordinator/coordinator_options.h"
#include "services/coordinator/coordinator_store.h"
#include "services/coordinator/dispatcher.h"
#include "services/coordinator/live_index.h"
#include "services/coordinator/ranking.h"
#include "services/coordinator/workers.h"

namespace meshseek {

class CoordinatorService final {
 public:
  static absl::StatusOr<std::unique_ptr<CoordinatorService>> Create(
      const CoordinatorOptions& options);
  ~CoordinatorService();

  /// Stops the dispatchers and build jobs (after the server has shut down).
  void Stop();

  absl::StatusOr<v1::Collection> CreateCollection(const v1::CreateCollectionRequest& request, const rpc::CallContext& call);
  absl::StatusOr<v1::Collection> GetCollection(const v1::GetCollectionRequest& request, const rpc::CallContext& call);
  absl::Status Ingest(rpc::Reader<v1::IngestRequest> read, rpc::Writer<v1::IngestAck> write, const rpc::CallContext& call);
  absl::StatusOr<v1::JobStatus> Build(const v1::BuildRequest& request, const rpc::CallContext& call);
  absl::StatusOr<v1::JobStatus> GetJob(const v1::JobRequest& request, const rpc::CallContext& call);
  absl::Status WatchJob(const v1::JobRequest& request, rpc::Writer<v1::JobStatus> write, const rpc::CallContext& call);
  absl::StatusOr<v1::QueryResponse> Query(const v1::QueryRequest& request, const rpc::CallContext& call);
  absl::StatusOr<v1::QueryResponse> QueryByImage(const v1::QueryByImageRequest& request, const rpc::CallContext& call);
  absl::StatusOr<v1::RemoveModelFromCollectionResponse> RemoveModel(const v1::RemoveModelFromCollectionRequest& request, const rpc::CallContext& call);
  absl::StatusOr<v1::ListCollectionModelsResponse> ListModels(const v1::ListCollectionModelsRequest& request, const rpc::CallContext& call);
  absl::StatusOr<v1::ListCollectionsResponse> ListCollections(const v1::ListCollectionsRequest& request, const rpc::CallContext& call);
  absl::StatusOr<v1::Thumbnail> GetThumbnail(const v1::GetThumbnailRequest& request, const rpc::CallContext& call);
  absl::Status Evaluate(const v1::EvaluateRequest& request, rpc::Writer<v1::EvaluateRow> write, const rpc::CallContext& call);

 private:
  CoordinatorService(const CoordinatorOptions& options, std::unique_ptr<CoordinatorStore> store);

  absl::StatusOr<v1::Collection> DescribeCollection(const std::string& name);
  // The plan of a collection clients may use: InvalidArgument for a member.
  absl::StatusOr<CollectionPlan> PublicPlan(const std::string& name);
  // Ingest of one model: validates, stores, returns the ack.
  // Query: the query's mesh (given, or a stored model's) as arrays, and
  // each part's signature of it (the parts extracted in parallel), with the
  // number of local features they found and the stages' times.
  absl::StatusOr<v1::Mesh> QueryMesh(const v1::QueryRequest& request, const CollectionPlan& plan);
  absl::StatusOr<std::vector<IndexSignature>> QuerySignatures(const v1::Mesh& mesh,
                                                              const CollectionPlan& plan,
                                                              uint32_t* features,
                                                              v1::QueryTimings* timings);
  absl::StatusOr<v1::IngestAck> AcceptModel(const v1::IngestRequest& request,
                                            const std::vector<std::string>& parts,
                                            const std::string& job_id);

  const CoordinatorOptions options_;
  std::atomic<bool> stop_{false};
  std::unique_ptr<CoordinatorStore> store_;
  Workers workers_;
  LiveIndex live_;
  Dispatcher dispatcher_;
  BuildRunner builds_;
  // Last: unregistered (waiting for a scrape in progress) before the store goes.
  std::unique_ptr<rpc::ScrapeGauge> models_gauge_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_SERVICE_H_
