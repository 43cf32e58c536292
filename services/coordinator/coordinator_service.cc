#include "services/coordinator/coordinator_service.h"

#include <cctype>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/base/logging.h"
#include "common/base/status_macros.h"
#include "common/render/thumbnail.h"
#include "common/rpc/convert.h"
#include "common/rpc/status.h"

namespace meshseek {
namespace {

absl::Status CheckName(const std::string& what, const std::string& name, std::size_t max_size,
                       bool identifier_chars) {
  if (name.empty() || name.size() > max_size) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " must have 1 to ", max_size, " characters, got '",
                     name.substr(0, 64), name.size() > 64 ? "...'" : "'"));
  }
  for (char c : name) {
    const bool ok = identifier_chars ? (std::isalnum(static_cast<unsigned char>(c)) || c == '.' ||
                                        c == '_' || c == '-')
                                     : (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f);
    if (!ok) {
      return absl::InvalidArgumentError(absl::StrCat(what, " '", name, "' has a character not in ",
                                                     identifier_chars ? "[A-Za-z0-9._-]" : "printable text"));
    }
  }
  return absl::OkStatus();
}

absl::Status Prefixed(const absl::Status& status, const std::string& prefix) {
  return absl::Status(status.code(), absl::StrCat(prefix, status.message()));
}

// meshseek_coordinator_models: every stored collection with all three
// states, zeros included, so that each series exists from the first model.
absl::StatusOr<std::vector<rpc::GaugeSample>> ModelsByState(CoordinatorStore* store) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<CoordinatorStore::StateCount> counts,
                            store->CountModelsByState());
  std::map<std::string, std::map<ModelState, uint64_t>> by_collection;
  for (const CoordinatorStore::StateCount& count : counts) {
    by_collection[count.collection][count.state] += count.models;
  }
  std::vector<rpc::GaugeSample> samples;
  for (const auto& [collection, states] : by_collection) {
    for (const auto& [state, name] : {std::pair{ModelState::kPending, "pending"},
                                      std::pair{ModelState::kExtracted, "extracted"},
                                      std::pair{ModelState::kFailed, "failed"}}) {
      const auto it = states.find(state);
      samples.push_back({{{"collection", collection}, {"state", name}},
                         it == states.end() ? 0.0 : static_cast<double>(it->second)});
    }
  }
  return samples;
}

}  // namespace

CoordinatorService::CoordinatorService(const CoordinatorOptions& options,
                                       std::unique_ptr<CoordinatorStore> store)
    : options_(options),
      store_(std::move(store)),
      workers_(options, &stop_),
      live_(store_.get(), &workers_),
      dispatcher_(store_.get(), &workers_, &live_, options_, &stop_),
      builds_(store_.get(), &workers_, &live_, options_, &stop_) {}

absl::StatusOr<std::unique_ptr<CoordinatorService>> CoordinatorService::Create(
    const CoordinatorOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<std::string> shards,
                            IndexShards::ParseTargets(options.index_target));
  MESHSEEK_ASSIGN_OR_RETURN(std::unique_ptr<CoordinatorStore> store,
                            CoordinatorStore::Open(options.data_dir, static_cast<int>(shards.size())));
  std::unique_ptr<CoordinatorService> service(new CoordinatorService(options, std::move(store)));
  service->dispatcher_.Start();
  MESHSEEK_RETURN_IF_ERROR(service->builds_.ResumeInterrupted());
  CoordinatorStore* counted = service->store_.get();
  service->models_gauge_ = rpc::ScrapeGauge::Register(
      "meshseek_coordinator_models",
      "Models stored per collection and state (a fused collection's are in its members)",
      [counted] { return ModelsByState(counted); });
  return service;
}

CoordinatorService::~CoordinatorService() { Stop(); }

void CoordinatorService::Stop() {
  if (stop_.exchange(true)) return;
  dispatcher_.Join();
  builds_.Join();
}

// ---------------------------------------------------------------- collections

absl::StatusOr<CollectionPlan> CoordinatorService::PublicPlan(const std::string& name) {
  MESHSEEK_ASSIGN_OR_RETURN(CollectionPlan plan, LoadCollectionPlan(store_.get(), name));
  if (plan.member) {
    return absl::InvalidArgumentError(absl::StrCat("collection '",
                                                   name,
                                                   "' is a member of '",
                                                   name.substr(0, name.find('~')),
                                                   "': use that one"));
  }
  return plan;
}

absl::StatusOr<v1::Collection> CoordinatorService::DescribeCollection(const std::string& name) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, LoadCollectionPlan(store_.get(), name));
  MESHSEEK_ASSIGN_OR_RETURN(const ModelCounts counts,
                            store_->CountModels(plan.PartNames(), plan.build()));
  v1::Collection collection;
  collection.set_name(name);
  *collection.mutable_params() = plan.params;
  collection.set_codebook_id(plan.codebook_id);
  collection.set_models(counts.models);
  collection.set_extracted(counts.extracted);
  collection.set_indexed(counts.indexed);
  collection.set_failed(counts.failed);
  collection.set_pending(counts.pending);
  collection.set_added_since_build(counts.added);
  return collection;
}

grpc::Status CoordinatorService::CreateCollection(grpc::ServerContext*,
                                                  const v1::CreateCollectionRequest* request,
                                                  v1::Collection* response) {
  if (absl::Status name = CheckName("collection name", request->name(), 128, true); !name.ok()) {
    return rpc::ToGrpcStatus(name);
  }
  absl::StatusOr<CollectionOptions> valid = rpc::CollectionOptionsFromParams(request->params());
  if (!valid.ok()) {
    return rpc::ToGrpcStatus(Prefixed(valid.status(), absl::StrCat("collection '", request->name(), "': ")));
  }
  for (const RetrievalPipelineOptions& method : valid->methods) {
    if (method.weighting.idf) {
      return grpc::Status(
          grpc::StatusCode::INVALID_ARGUMENT,
          absl::StrCat("collection '",
                       request->name(),
                       "': idf=true needs the whole "
                       "collection's document frequencies, which the services do not keep; "
                       "evaluate it in process (meshseek eval --server in-process)"));
    }
  }
  // Stored canonical: every parameter with its value, so the collection
  // keeps its meaning when a default changes, and creating it again with the
  // same parameters however written is not a conflict.
  v1::PipelineParams canonical;
  rpc::CollectionParamsToProto(*valid, &canonical);
  if (absl::StatusOr<StoredCollection> existing = store_->GetCollection(request->name());
      existing.ok()) {
    absl::StatusOr<CollectionOptions> stored = rpc::CollectionOptionsFromParams(existing->params);
    v1::PipelineParams stored_canonical;
    if (stored.ok()) rpc::CollectionParamsToProto(*stored, &stored_canonical);
    if (!stored.ok() || stored_canonical.SerializeAsString() != canonical.SerializeAsString()) {
      return grpc::Status(
          grpc::StatusCode::ALREADY_EXISTS,
          absl::StrCat("collection '", request->name(), "' exists with other parameters"));
    }
  } else {
    // A fused collection and its members, one per method, together.
    std::vector<std::pair<std::string, v1::PipelineParams>> rows = {{request->name(), canonical}};
    if (valid->fused()) {
      for (const RetrievalPipelineOptions& method : valid->methods) {
        v1::PipelineParams params;
        rpc::PipelineParamsToProto(method, &params);
        rows.emplace_back(MemberCollectionName(request->name(), method.extractor.method), params);
      }
    }
    if (absl::Status s = store_->CreateCollections(rows); !s.ok()) return rpc::ToGrpcStatus(s);
  }
  absl::StatusOr<v1::Collection> collection = DescribeCollection(request->name());
  if (!collection.ok()) return rpc::ToGrpcStatus(collection.status());
  *response = *std::move(collection);
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::GetCollection(grpc::ServerContext*,
                                               const v1::GetCollectionRequest* request,
                                               v1::Collection* response) {
  absl::StatusOr<v1::Collection> collection = DescribeCollection(request->name());
  if (!collection.ok()) return rpc::ToGrpcStatus(collection.status());
  *response = *std::move(collection);
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::ListCollections(grpc::ServerContext*,
                                                 const v1::ListCollectionsRequest*,
                                                 v1::ListCollectionsResponse* response) {
  absl::StatusOr<std::vector<std::string>> names = store_->ListCollectionNames();
  if (!names.ok()) return rpc::ToGrpcStatus(names.status());
  for (const std::string& name : *names) {
    absl::StatusOr<v1::Collection> collection = DescribeCollection(name);
    // Removed meanwhile, or parameters this release cannot read: skip it
    // here; GetCollection says why.
    if (!collection.ok()) continue;
    *response->add_collections() = *std::move(collection);
  }
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::GetThumbnail(grpc::ServerContext*,
                                              const v1::GetThumbnailRequest* request,
                                              v1::Thumbnail* response) {
  absl::StatusOr<CollectionPlan> plan = PublicPlan(request->collection());
  if (!plan.ok()) return rpc::ToGrpcStatus(plan.status());
  const ModelKey key{request->collection(), request->model_id()};
  absl::StatusOr<std::optional<std::string>> png = store_->GetThumbnail(key);
  if (!png.ok()) return rpc::ToGrpcStatus(png.status());
  if (png->has_value()) {
    response->set_png(**std::move(png));
    return grpc::Status::OK;
  }
  // Not drawn at ingest (stored by an earlier release, or not drawable):
  // draw it from the stored mesh now and keep it.
  absl::StatusOr<std::optional<std::string>> stored =
      store_->ModelMesh({plan->parts.front().name, request->model_id()});
  if (!stored.ok()) return rpc::ToGrpcStatus(stored.status());
  if (!stored->has_value()) {
    return grpc::Status(
        grpc::StatusCode::NOT_FOUND,
        absl::StrCat(
            "collection '", request->collection(), "' has no model '", request->model_id(), "'"));
  }
  v1::MeshInput input;
  if (!input.mutable_mesh()->ParseFromString(**stored)) {
    return grpc::Status(
        grpc::StatusCode::DATA_LOSS,
        absl::StrCat("model ", request->model_id(), ": stored mesh does not parse"));
  }
  absl::StatusOr<TriangleMesh> mesh = rpc::MeshFromProto(input, options_.mesh_limits);
  if (!mesh.ok()) return rpc::ToGrpcStatus(mesh.status());
  absl::StatusOr<std::string> drawn = RenderThumbnailPng(*mesh);
  if (!drawn.ok()) {
    return grpc::Status(
        grpc::StatusCode::FAILED_PRECONDITION,
        absl::StrCat(
            "model ", request->model_id(), ": no thumbnail (", drawn.status().message(), ")"));
  }
  if (absl::Status s = store_->SetThumbnail(key, *drawn); !s.ok()) return rpc::ToGrpcStatus(s);
  response->set_png(*std::move(drawn));
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::ListModels(grpc::ServerContext*,
                                            const v1::ListCollectionModelsRequest* request,
                                            v1::ListCollectionModelsResponse* response) {
  absl::StatusOr<CollectionPlan> plan = PublicPlan(request->collection());
  if (!plan.ok()) return rpc::ToGrpcStatus(plan.status());
  absl::StatusOr<v1::ListCollectionModelsResponse> models =
      store_->ListModels(*request, plan->fused() ? plan->PartNames() : std::vector<std::string>());
  if (!models.ok()) return rpc::ToGrpcStatus(models.status());
  *response = *std::move(models);
  return grpc::Status::OK;
}

// ----------------------------------------------------------------------- jobs

grpc::Status CoordinatorService::GetJob(grpc::ServerContext*,
                                        const v1::JobRequest* request,
                                        v1::JobStatus* response) {
  absl::StatusOr<v1::JobStatus> status = store_->GetJob(request->job_id());
  if (!status.ok()) return rpc::ToGrpcStatus(status.status());
  *response = *std::move(status);
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::WatchJob(grpc::ServerContext* context,
                                          const v1::JobRequest* request,
                                          grpc::ServerWriter<v1::JobStatus>* writer) {
  std::string last;
  while (!context->IsCancelled() && !stop_) {
    absl::StatusOr<v1::JobStatus> status = store_->GetJob(request->job_id());
    if (!status.ok()) return rpc::ToGrpcStatus(status.status());
    const std::string now = status->SerializeAsString();
    if (now != last && !writer->Write(*status)) return grpc::Status::CANCELLED;
    last = now;
    if (status->state() != v1::JOB_STATE_RUNNING) return grpc::Status::OK;
    absl::SleepFor(absl::Milliseconds(200));
  }
  return grpc::Status(grpc::StatusCode::CANCELLED, "watch ended: the coordinator is stopping");
}

// --------------------------------------------------------------------- ingest

absl::StatusOr<v1::IngestAck> CoordinatorService::AcceptModel(const v1::IngestRequest& request,
                                                              const std::vector<std::string>& parts,
                                                              const std::string& job_id) {
  MESHSEEK_RETURN_IF_ERROR(CheckName("model id", request.model_id(), 256, false));
  if (request.label().size() > 256) {
    return absl::InvalidArgumentError(absl::StrCat("model ", request.model_id(), ": label of ",
                                                   request.label().size(),
                                                   " bytes, more than 256"));
  }
  absl::StatusOr<TriangleMesh> mesh = rpc::MeshFromProto(request.mesh(), options_.mesh_limits);
  if (!mesh.ok()) return Prefixed(mesh.status(), absl::StrCat("model ", request.model_id(), ": "));
  v1::Mesh stored;
  rpc::MeshToProto(*mesh, &stored);
  // A mesh that cannot be drawn (no extent) is still taken: extraction
  // decides whether it is usable, and says why not.
  CoordinatorStore::ModelThumbnail thumbnail{request.collection(), ""};
  if (absl::StatusOr<std::string> png = RenderThumbnailPng(*mesh); png.ok()) {
    thumbnail.png = *std::move(png);
  } else {
    MESHSEEK_LOG(WARNING) << "model " << request.model_id() << ": no thumbnail: " << png.status();
  }
  MESHSEEK_ASSIGN_OR_RETURN(const CoordinatorStore::AddedModel added,
                            store_->AddModel(parts,
                                             request.model_id(),
                                             request.label(),
                                             stored.SerializeAsString(),
                                             job_id,
                                             thumbnail));
  if (added.rows > 0) dispatcher_.ModelAdded(added.rows);
  v1::IngestAck ack;
  ack.set_model_id(request.model_id());
  ack.set_job_id(added.job_id);
  ack.set_created(added.created);
  return ack;
}

grpc::Status CoordinatorService::Ingest(
    grpc::ServerContext* context,
    grpc::ServerReaderWriter<v1::IngestAck, v1::IngestRequest>* stream) {
  std::string job_id;
  std::string collection;
  std::vector<std::string> parts;  // where its models are stored
  v1::IngestRequest request;
  grpc::Status result = grpc::Status::OK;
  while (stream->Read(&request)) {
    if (job_id.empty()) {
      absl::StatusOr<CollectionPlan> plan = PublicPlan(request.collection());
      if (!plan.ok()) return rpc::ToGrpcStatus(plan.status());
      parts = plan->PartNames();
      absl::StatusOr<std::string> job = store_->NewJob("ingest", request.collection(), 0);
      if (!job.ok()) return rpc::ToGrpcStatus(job.status());
      job_id = *job;
      collection = request.collection();
    } else if (request.collection() != collection) {
      result = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                            absl::StrCat("model ", request.model_id(), ": an ingest stream is for "
                                         "one collection ('", collection, "'), not '",
                                         request.collection(), "'"));
      break;
    }
    // Backpressure: hold the acknowledgement while too much work waits.
    if (!dispatcher_.WaitForRoom([context] { return context->IsCancelled(); })) {
      result = grpc::Status(grpc::StatusCode::CANCELLED, "ingest cancelled");
      break;
    }
    absl::StatusOr<v1::IngestAck> ack = AcceptModel(request, parts, job_id);
    if (!ack.ok()) {
      result = rpc::ToGrpcStatus(ack.status());
      break;
    }
    if (!stream->Write(*ack)) {
      result = grpc::Status(grpc::StatusCode::CANCELLED, "ingest stream closed by the client");
      break;
    }
  }
  if (!job_id.empty()) {
    if (absl::Status s = store_->CloseIngestStream(job_id); !s.ok() && result.ok()) {
      result = rpc::ToGrpcStatus(s);
    }
  }
  return result;
}

// ---------------------------------------------------------------------- build

grpc::Status CoordinatorService::Build(grpc::ServerContext*,
                                       const v1::BuildRequest* request,
                                       v1::JobStatus* response) {
  absl::StatusOr<std::string> job = builds_.Start(request->collection());
  if (!job.ok()) return rpc::ToGrpcStatus(job.status());
  v1::JobRequest get;
  get.set_job_id(*job);
  return GetJob(nullptr, &get, response);
}

// ------------------------------------------------------- query, remove, eval

grpc::Status CoordinatorService::RemoveModel(grpc::ServerContext*,
                                             const v1::RemoveModelFromCollectionRequest* request,
                                             v1::RemoveModelFromCollectionResponse* response) {
  absl::StatusOr<CollectionPlan> plan = PublicPlan(request->collection());
  if (!plan.ok()) return rpc::ToGrpcStatus(plan.status());
  bool removed = false;
  for (const std::string& part : plan->PartNames()) {
    // The index first: a failure there leaves the model in both, and the
    // removal can simply be retried.
    absl::StatusOr<bool> unindexed = workers_.index()->Remove(part, request->model_id());
    if (!unindexed.ok()) return rpc::ToGrpcStatus(unindexed.status());
    absl::StatusOr<std::optional<ModelState>> state =
        store_->RemoveModel({part, request->model_id()});
    if (!state.ok()) return rpc::ToGrpcStatus(state.status());
    if (*state == ModelState::kPending) dispatcher_.PendingModelRemoved();
    removed = removed || state->has_value();
  }
  if (absl::Status s = store_->RemoveThumbnail({request->collection(), request->model_id()});
      !s.ok()) {
    return rpc::ToGrpcStatus(s);
  }
  response->set_removed(removed);
  return grpc::Status::OK;
}

}  // namespace meshseek
