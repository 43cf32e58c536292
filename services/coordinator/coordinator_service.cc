#include "services/coordinator/coordinator_service.h"

#include <cctype>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/base/logging.h"
#include "common/base/status_macros.h"
#include "common/pipeline/pipeline_params.h"
#include "common/render/thumbnail.h"
#include "common/wire/convert.h"

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

namespace {

// A new collection whose parameters name no method, by value or by a legacy
// field, is the default fusion (kDefaultCollectionMethods); a stored one
// never reaches this (it is stored with every value, its method first), and
// a request with legacy fields only keeps their meaning (dld).
v1::PipelineParams WithDefaultMethods(const v1::PipelineParams& params) {
  for (const v1::ParamValue& v : params.values()) {
    if (v.name() == "method") return params;
  }
  v1::PipelineParams legacy = params;
  legacy.clear_values();
  if (legacy.ByteSizeLong() != 0) return params;
  v1::PipelineParams named = params;
  v1::ParamValue* method = named.add_values();
  method->set_name("method");
  method->set_value(kDefaultCollectionMethods);
  // The method first: every other value reads in its light.
  for (int i = named.values_size() - 1; i > 0; --i) named.mutable_values()->SwapElements(i, i - 1);
  return named;
}

}  // namespace

absl::StatusOr<v1::Collection> CoordinatorService::CreateCollection(
    const v1::CreateCollectionRequest& request, const rpc::CallContext&) {
  MESHSEEK_RETURN_IF_ERROR(CheckName("collection name", request.name(), 128, true));
  const std::string where = absl::StrCat("collection '", request.name(), "'");
  absl::StatusOr<CollectionOptions> valid =
      wire::CollectionOptionsFromParams(WithDefaultMethods(request.params()));
  if (!valid.ok()) return Prefixed(valid.status(), where + ": ");
  for (const RetrievalPipelineOptions& method : valid->methods) {
    if (method.weighting.idf) {
      return absl::InvalidArgumentError(absl::StrCat(
          where,
          ": idf=true needs the whole "
          "collection's document frequencies, which the services do not keep; "
          "evaluate it in process (meshseek eval --server in-process)"));
    }
  }
  // Stored canonical: every parameter with its value, so the collection
  // keeps its meaning when a default changes, and creating it again with the
  // same parameters however written is not a conflict.
  v1::PipelineParams canonical;
  wire::CollectionParamsToProto(*valid, &canonical);
  if (absl::StatusOr<StoredCollection> existing = store_->GetCollection(request.name());
      existing.ok()) {
    absl::StatusOr<CollectionOptions> stored = wire::CollectionOptionsFromParams(existing->params);
    v1::PipelineParams stored_canonical;
    if (stored.ok()) wire::CollectionParamsToProto(*stored, &stored_canonical);
    if (!stored.ok() || stored_canonical.SerializeAsString() != canonical.SerializeAsString()) {
      return absl::AlreadyExistsError(absl::StrCat(where, " exists with other parameters"));
    }
  } else {
    // A fused collection and its members, one per method, together.
    std::vector<std::pair<std::string, v1::PipelineParams>> rows = {{request.name(), canonical}};
    if (valid->fused()) {
      for (const RetrievalPipelineOptions& method : valid->methods) {
        v1::PipelineParams params;
        wire::PipelineParamsToProto(method, &params);
        rows.emplace_back(MemberCollectionName(request.name(), method.extractor.method), params);
      }
    }
    MESHSEEK_RETURN_IF_ERROR(store_->CreateCollections(rows));
  }
  return DescribeCollection(request.name());
}

absl::StatusOr<v1::Collection> CoordinatorService::GetCollection(
    const v1::GetCollectionRequest& request, const rpc::CallContext&) {
  return DescribeCollection(request.name());
}

absl::StatusOr<v1::ListCollectionsResponse> CoordinatorService::ListCollections(
    const v1::ListCollectionsRequest&, const rpc::CallContext&) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<std::string> names, store_->ListCollectionNames());
  v1::ListCollectionsResponse response;
  for (const std::string& name : names) {
    absl::StatusOr<v1::Collection> collection = DescribeCollection(name);
    // Removed meanwhile, or parameters this release cannot read: skip it
    // here; GetCollection says why.
    if (!collection.ok()) continue;
    *response.add_collections() = *std::move(collection);
  }
  return response;
}

absl::StatusOr<v1::Thumbnail> CoordinatorService::GetThumbnail(
    const v1::GetThumbnailRequest& request, const rpc::CallContext&) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, PublicPlan(request.collection()));
  const ModelKey key{request.collection(), request.model_id()};
  MESHSEEK_ASSIGN_OR_RETURN(std::optional<std::string> png, store_->GetThumbnail(key));
  v1::Thumbnail response;
  if (png.has_value()) {
    response.set_png(*std::move(png));
    return response;
  }
  // Not drawn at ingest (stored by an earlier release, or not drawable):
  // draw it from the stored mesh now and keep it.
  MESHSEEK_ASSIGN_OR_RETURN(const std::optional<std::string> stored,
                            store_->ModelMesh({plan.parts.front().name, request.model_id()}));
  if (!stored.has_value()) {
    return absl::NotFoundError(absl::StrCat(
        "collection '", request.collection(), "' has no model '", request.model_id(), "'"));
  }
  const std::string model = absl::StrCat("model ", request.model_id(), ": ");
  v1::MeshInput input;
  if (!input.mutable_mesh()->ParseFromString(*stored)) {
    return absl::DataLossError(model + "stored mesh does not parse");
  }
  MESHSEEK_ASSIGN_OR_RETURN(const TriangleMesh mesh,
                            wire::MeshFromProto(input, options_.mesh_limits));
  absl::StatusOr<std::string> drawn = RenderThumbnailPng(mesh);
  if (!drawn.ok()) {
    return absl::FailedPreconditionError(
        absl::StrCat(model, "no thumbnail (", drawn.status().message(), ")"));
  }
  MESHSEEK_RETURN_IF_ERROR(store_->SetThumbnail(key, *drawn));
  response.set_png(*std::move(drawn));
  return response;
}

absl::StatusOr<v1::ListCollectionModelsResponse> CoordinatorService::ListModels(
    const v1::ListCollectionModelsRequest& request, const rpc::CallContext&) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, PublicPlan(request.collection()));
  return store_->ListModels(request, plan.fused() ? plan.PartNames() : std::vector<std::string>());
}

// ----------------------------------------------------------------------- jobs

absl::StatusOr<v1::JobStatus> CoordinatorService::GetJob(const v1::JobRequest& request,
                                                         const rpc::CallContext&) {
  return store_->GetJob(request.job_id());
}

absl::Status CoordinatorService::WatchJob(const v1::JobRequest& request,
                                          rpc::Writer<v1::JobStatus> write,
                                          const rpc::CallContext& call) {
  std::string last;
  while (!call.cancelled() && !stop_) {
    MESHSEEK_ASSIGN_OR_RETURN(const v1::JobStatus status, store_->GetJob(request.job_id()));
    const std::string now = status.SerializeAsString();
    if (now != last && !write(status)) return absl::CancelledError("");
    last = now;
    if (status.state() != v1::JOB_STATE_RUNNING) return absl::OkStatus();
    absl::SleepFor(absl::Milliseconds(200));
  }
  return absl::CancelledError("watch ended: the coordinator is stopping");
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
  absl::StatusOr<TriangleMesh> mesh = wire::MeshFromProto(request.mesh(), options_.mesh_limits);
  if (!mesh.ok()) return Prefixed(mesh.status(), absl::StrCat("model ", request.model_id(), ": "));
  v1::Mesh stored;
  wire::MeshToProto(*mesh, &stored);
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

absl::Status CoordinatorService::Ingest(rpc::Reader<v1::IngestRequest> read,
                                        rpc::Writer<v1::IngestAck> write,
                                        const rpc::CallContext& call) {
  std::string job_id;
  std::string collection;
  std::vector<std::string> parts;  // where its models are stored
  v1::IngestRequest request;
  absl::Status result;
  while (read(&request)) {
    if (job_id.empty()) {
      MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, PublicPlan(request.collection()));
      parts = plan.PartNames();
      MESHSEEK_ASSIGN_OR_RETURN(job_id, store_->NewJob("ingest", request.collection(), 0));
      collection = request.collection();
    } else if (request.collection() != collection) {
      result = absl::InvalidArgumentError(absl::StrCat(
          "model ", request.model_id(), ": an ingest stream is for one collection ('", collection,
          "'), not '", request.collection(), "'"));
      break;
    }
    // Backpressure: hold the acknowledgement while too much work waits.
    if (!dispatcher_.WaitForRoom([&call] { return call.cancelled(); })) {
      result = absl::CancelledError("ingest cancelled");
      break;
    }
    absl::StatusOr<v1::IngestAck> ack = AcceptModel(request, parts, job_id);
    if (!ack.ok()) {
      result = ack.status();
      break;
    }
    if (!write(*ack)) {
      result = absl::CancelledError("ingest stream closed by the client");
      break;
    }
  }
  if (!job_id.empty()) {
    if (absl::Status s = store_->CloseIngestStream(job_id); !s.ok() && result.ok()) result = s;
  }
  return result;
}

// ---------------------------------------------------------------------- build

absl::StatusOr<v1::JobStatus> CoordinatorService::Build(const v1::BuildRequest& request,
                                                        const rpc::CallContext&) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::string job, builds_.Start(request.collection()));
  return store_->GetJob(job);
}

// ------------------------------------------------------- query, remove, eval

absl::StatusOr<v1::RemoveModelFromCollectionResponse> CoordinatorService::RemoveModel(
    const v1::RemoveModelFromCollectionRequest& request, const rpc::CallContext&) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, PublicPlan(request.collection()));
  bool removed = false;
  for (const std::string& part : plan.PartNames()) {
    // The index first: a failure there leaves the model in both, and the
    // removal can simply be retried.
    MESHSEEK_RETURN_IF_ERROR(workers_.index()->Remove(part, request.model_id()).status());
    MESHSEEK_ASSIGN_OR_RETURN(const std::optional<ModelState> state,
                              store_->RemoveModel({part, request.model_id()}));
    if (state == ModelState::kPending) dispatcher_.PendingModelRemoved();
    removed = removed || state.has_value();
  }
  MESHSEEK_RETURN_IF_ERROR(store_->RemoveThumbnail({request.collection(), request.model_id()}));
  v1::RemoveModelFromCollectionResponse response;
  response.set_removed(removed);
  return response;
}

}  // namespace meshseek
