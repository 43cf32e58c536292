#include "cli/coordinator_client.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/clock.h"
#include "common/base/progress.h"
#include "common/base/status_macros.h"
#include "common/rpc/status.h"
#include "common/wire/convert.h"

namespace meshseek::cli {

std::vector<ModelToIngest> ModelsOfManifest(const std::vector<ManifestEntry>& entries) {
  std::vector<ModelToIngest> models;
  for (const ManifestEntry& e : entries) {
    models.push_back(
        {e.id, e.label, e.path, absl::StrCat("model '", e.id, "' (manifest line ", e.line, ")")});
  }
  return models;
}

absl::StatusOr<std::unique_ptr<CoordinatorClient>> CoordinatorClient::Open(
    const ClientOptions& options) {
  std::unique_ptr<CoordinatorClient> client(new CoordinatorClient());
  client->options_ = options;
  client->retry_.attempts = 1 + static_cast<int>(options.reconnect_for / absl::Seconds(2));
  client->retry_.max_backoff = absl::Seconds(2);
  std::string address = options.server;
  if (address.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(
        client->stack_,
        EmbeddedStack::Start(options.data_dir, options.threads, 0, {}, options.mesh_limits));
    address = client->stack_->coordinator_address();
  }
  rpc::ChannelOptions channel;
  channel.retry_service = "";  // the client retries itself, knowing what is idempotent
  if (client->stack_ == nullptr) {
    MESHSEEK_ASSIGN_OR_RETURN(channel, rpc::WithClientSecurity(options.security, channel));
  }
  client->stub_ = v1::Coordinator::NewStub(rpc::MakeChannel(address, channel));
  return client;
}

absl::StatusOr<v1::JobStatus> CoordinatorClient::WaitForJob(const std::string& job_id,
                                                            const std::string& label) {
  std::unique_ptr<ProgressBar> bar;
  v1::JobStatus status;
  std::size_t shown = 0;
  absl::Time give_up = absl::Now() + options_.reconnect_for;
  while (true) {
    grpc::ClientContext context;
    v1::JobRequest request;
    request.set_job_id(job_id);
    auto reader = stub_->WatchJob(&context, request);
    while (reader->Read(&status)) {
      give_up = absl::Now() + options_.reconnect_for;
      if (!bar && status.total() > 0) {
        bar = std::make_unique<ProgressBar>(label, status.total(), options_.progress);
      }
      if (bar && status.done() > shown) {
        bar->Advance(status.done() - shown);
        shown = status.done();
      }
    }
    const absl::Status end = rpc::FromGrpcStatus(reader->Finish());
    if (end.ok() && status.state() != v1::JOB_STATE_RUNNING) break;
    if (!end.ok() && !rpc::IsTransient(end)) return end;
    if (absl::Now() > give_up) {
      return absl::UnavailableError(
          absl::StrCat("lost the coordinator while waiting for ", job_id, ": ", end.message()));
    }
    absl::SleepFor(absl::Milliseconds(500));
  }
  if (bar) bar->Finish();
  if (status.state() == v1::JOB_STATE_FAILED) {
    std::string errors;
    for (const std::string& e : status.errors()) absl::StrAppend(&errors, "\n  ", e);
    return absl::FailedPreconditionError(
        absl::StrCat(job_id, " failed: ", status.message(), errors));
  }
  return status;
}

absl::Status CoordinatorClient::Ingest(const std::string& collection,
                                       const std::vector<ModelToIngest>& models) {
  // Guards the map of unacknowledged models and the acknowledgement flags
  // the reader thread sets.
  absl::Mutex sent_mutex;
  std::vector<bool> acked(models.size(), false);
  std::vector<std::string> jobs;
  std::size_t created = 0;
  ProgressBar bar("ingest", models.size(), options_.progress);
  absl::Time give_up = absl::Now() + options_.reconnect_for;
  while (true) {
    grpc::ClientContext context;
    auto stream = stub_->Ingest(&context);
    std::map<std::string, std::size_t> sent;  // model id -> index, awaiting acknowledgement
    // Acknowledgements arrive on their own thread while this one sends.
    std::thread reader([&] {
      v1::IngestAck ack;
      while (stream->Read(&ack)) {
        {
          absl::MutexLock lock(&sent_mutex);
          auto it = sent.find(ack.model_id());
          if (it == sent.end()) continue;
          acked[it->second] = true;
          sent.erase(it);
        }
        if (ack.created()) ++created;
        if (std::find(jobs.begin(), jobs.end(), ack.job_id()) == jobs.end()) jobs.push_back(ack.job_id());
        bar.Advance();
      }
    });
    for (std::size_t i = 0; i < models.size(); ++i) {
      {
        // The reader thread sets acknowledgements (vector<bool> packs them
        // into shared words: every access under the mutex).
        absl::MutexLock lock(&sent_mutex);
        if (acked[i]) continue;
      }
      const ModelToIngest& m = models[i];
      absl::StatusOr<TriangleMesh> mesh = ReadMesh(m.path, nullptr, options_.mesh_limits);
      if (!mesh.ok()) {
        stream->WritesDone();
        reader.join();
        return absl::Status(mesh.status().code(),
                            absl::StrCat(m.where, ": ", mesh.status().message()));
      }
      v1::IngestRequest request;
      request.set_collection(collection);
      request.set_model_id(m.id);
      request.set_label(m.label);
      wire::MeshToProto(*mesh, request.mutable_mesh()->mutable_mesh());
      {
        absl::MutexLock lock(&sent_mutex);
        sent[m.id] = i;
      }
      if (!stream->Write(request)) break;
    }
    stream->WritesDone();
    reader.join();
    const absl::Status status = rpc::FromGrpcStatus(stream->Finish());
    const bool all = std::all_of(acked.begin(), acked.end(), [](bool b) { return b; });
    if (status.ok() && all) break;
    if (!status.ok() && !rpc::IsTransient(status)) return status;
    if (absl::Now() > give_up) {
      return absl::UnavailableError(absl::StrCat("ingest: lost the coordinator: ", status.message()));
    }
    if (status.ok()) give_up = absl::Now() + options_.reconnect_for;
    absl::SleepFor(absl::Milliseconds(500));  // reconnect and send the rest
  }
  bar.Finish();
  std::fprintf(stderr, "ingest: %zu models acknowledged (%zu new)\n", models.size(), created);
  for (const std::string& job : jobs) {
    MESHSEEK_RETURN_IF_ERROR(WaitForJob(job, "extract").status());
  }
  return absl::OkStatus();
}

absl::Status CoordinatorClient::EnsureCollection(const std::string& name,
                                                 const flags::ParamFlags& params) {
  const absl::StatusOr<v1::Collection> existing = GetCollection(name);
  if (existing.ok()) return flags::CheckFlagsAgreeWith(params, existing->params(), name);
  if (!absl::IsNotFound(existing.status())) return existing.status();
  v1::CreateCollectionRequest create;
  create.set_name(name);
  MESHSEEK_ASSIGN_OR_RETURN(*create.mutable_params(), flags::CollectionParamsFromFlags(params));
  v1::Collection collection;
  return Call(&v1::Coordinator::Stub::CreateCollection, create, &collection);
}

absl::Status CoordinatorClient::Build(const std::string& name) {
  v1::BuildRequest build;
  build.set_collection(name);
  v1::JobStatus job;
  MESHSEEK_RETURN_IF_ERROR(Call(&v1::Coordinator::Stub::Build, build, &job));
  MESHSEEK_ASSIGN_OR_RETURN(const v1::JobStatus done, WaitForJob(job.job_id(), "build"));
  std::fprintf(stderr, "build: %s\n", done.message().c_str());
  return absl::OkStatus();
}

absl::StatusOr<v1::Collection> CoordinatorClient::GetCollection(const std::string& name) {
  v1::GetCollectionRequest get;
  get.set_name(name);
  v1::Collection collection;
  MESHSEEK_RETURN_IF_ERROR(Call(&v1::Coordinator::Stub::GetCollection, get, &collection));
  return collection;
}

absl::StatusOr<std::vector<v1::Collection>> CoordinatorClient::ListCollections() {
  v1::ListCollectionsResponse list;
  MESHSEEK_RETURN_IF_ERROR(
      Call(&v1::Coordinator::Stub::ListCollections, v1::ListCollectionsRequest(), &list));
  return std::vector<v1::Collection>(list.collections().begin(), list.collections().end());
}

absl::StatusOr<std::vector<v1::ModelInfo>> CoordinatorClient::FailedModels(
    const std::string& collection) {
  v1::ListCollectionModelsRequest list;
  list.set_collection(collection);
  list.set_state(v1::MODEL_STATE_FAILED);
  list.set_page_size(1000);
  std::vector<v1::ModelInfo> failed;
  while (true) {
    v1::ListCollectionModelsResponse page;
    MESHSEEK_RETURN_IF_ERROR(Call(&v1::Coordinator::Stub::ListModels, list, &page));
    failed.insert(failed.end(), page.models().begin(), page.models().end());
    if (page.next_page_token().empty()) return failed;
    list.set_page_token(page.next_page_token());
  }
}

}  // namespace meshseek::cli
