// The gRPC client commands: ingest, build, query, status, serve, and eval
// through the services. Without --server each command starts the embedded
// stack on --data_dir for its duration.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "absl/flags/declare.h"
#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/clock.h"
#include "cli/commands.h"
#include "cli/embedded_stack.h"
#include "cli/output_format.h"
#include "cli/pipeline_flags.h"
#include "cli/session.h"
#include "common/base/hash.h"
#include "common/base/progress.h"
#include "common/base/status_macros.h"
#include "common/geometry/mesh_io.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/rpc/client.h"
#include "common/rpc/convert.h"
#include "common/rpc/mesh_limit_flags.h"
#include "common/rpc/server.h"
#include "common/rpc/status.h"
#include "meshseek/v1/coordinator.grpc.pb.h"

ABSL_FLAG(std::string, collection, "",
          "collection name (eval: default <manifest folder>-<method>-<parameter hash>)");
ABSL_FLAG(std::string, folder, "", "ingest: every mesh file in this folder (id = file name)");
ABSL_FLAG(int, top_k, 10, "query: results to print");
ABSL_FLAG(int, candidates, 0,
          "query: 0 searches exactly; N re-ranks the N candidates an embedding proposes "
          "(faster on large collections, may miss a neighbour); on a fused collection each "
          "histogram method proposes N and their union is fused and re-ranked (100: recall@10 "
          "0.99 on the development sets)");
ABSL_FLAG(std::string, job, "", "status: a job id to follow until it ends");
ABSL_FLAG(int,
          metrics_port,
          0,
          "serve: Prometheus metrics of all five services on 127.0.0.1:PORT/metrics; 0: none");
// Defined in session.cc.
ABSL_DECLARE_FLAG(std::string, server);
ABSL_DECLARE_FLAG(std::string, data_dir);
ABSL_DECLARE_FLAG(std::string, tls_ca);
ABSL_DECLARE_FLAG(std::string, tls_cert);
ABSL_DECLARE_FLAG(std::string, tls_key);
ABSL_DECLARE_FLAG(std::string, token_file);
ABSL_DECLARE_FLAG(absl::Duration, reconnect_for);
// Defined in eval_command.cc.
ABSL_DECLARE_FLAG(std::string, manifest);
ABSL_DECLARE_FLAG(std::string, out);
ABSL_DECLARE_FLAG(bool, progress);
ABSL_DECLARE_FLAG(int, threads);

namespace meshseek::cli {
namespace {

// Guards the ingest stream's map of unacknowledged models and the
// acknowledgement flags the reader thread sets.
absl::Mutex sent_mutex_;

struct ModelToIngest {
  std::string id;
  std::string label;
  std::string path;
  std::string where;  // "model 'b' (manifest line 3)", for error messages
};

absl::StatusOr<std::vector<ModelToIngest>> ModelsFromFlags() {
  std::vector<ModelToIngest> models;
  const std::string manifest = absl::GetFlag(FLAGS_manifest);
  const std::string folder = absl::GetFlag(FLAGS_folder);
  if (!manifest.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ManifestEntry> entries, ReadManifest(manifest));
    for (const ManifestEntry& e : entries) {
      models.push_back({e.id, e.label, e.path,
                        absl::StrCat("model '", e.id, "' (manifest line ", e.line, ")")});
    }
  } else if (!folder.empty()) {
    std::error_code error;
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
      if (entry.is_regular_file() && MeshFormatFromPath(entry.path().string()).ok()) {
        files.push_back(entry.path());
      }
    }
    if (error) return absl::NotFoundError(absl::StrCat(folder, ": ", error.message()));
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      models.push_back({f.stem().string(), "", f.string(), absl::StrCat("model '", f.stem().string(), "'")});
    }
  } else {
    return absl::InvalidArgumentError("ingest needs --manifest FILE or --folder DIR");
  }
  return models;
}

// Follows a job until it ends, drawing its progress; survives coordinator
// restarts (the job is durable).
absl::StatusOr<v1::JobStatus> WaitForJob(v1::Coordinator::Stub* stub, const std::string& job_id,
                                         const std::string& label) {
  std::unique_ptr<ProgressBar> bar;
  v1::JobStatus status;
  std::size_t shown = 0;
  absl::Time give_up = absl::Now() + absl::GetFlag(FLAGS_reconnect_for);
  while (true) {
    grpc::ClientContext context;
    v1::JobRequest request;
    request.set_job_id(job_id);
    auto reader = stub->WatchJob(&context, request);
    while (reader->Read(&status)) {
      give_up = absl::Now() + absl::GetFlag(FLAGS_reconnect_for);
      if (!bar && status.total() > 0) {
        bar = std::make_unique<ProgressBar>(label, status.total(), absl::GetFlag(FLAGS_progress));
      }
      if (bar && status.done() > shown) {
        bar->Advance(status.done() - shown);
        shown = status.done();
      }
    }
    const absl::Status end = rpc::FromGrpcStatus(reader->Finish());
    if (end.ok() && status.state() != v1::JOB_STATE_RUNNING) break;
    if (!end.ok() && !rpc::IsTransient(end)) return end;
    if (absl::Now() > give_up) return absl::UnavailableError(absl::StrCat("lost the coordinator while waiting for ", job_id, ": ", end.message()));
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

// Streams every model to the coordinator (reconnecting and re-sending what
// was not acknowledged if the stream breaks), then waits for the jobs.
absl::Status IngestModels(v1::Coordinator::Stub* stub, const std::string& collection,
                          const std::vector<ModelToIngest>& models) {
  MESHSEEK_ASSIGN_OR_RETURN(const MeshReadOptions limits, rpc::MeshLimitsFromFlags());
  std::vector<bool> acked(models.size(), false);
  std::vector<std::string> jobs;
  std::size_t created = 0;
  ProgressBar bar("ingest", models.size(), absl::GetFlag(FLAGS_progress));
  absl::Time give_up = absl::Now() + absl::GetFlag(FLAGS_reconnect_for);
  while (true) {
    grpc::ClientContext context;
    auto stream = stub->Ingest(&context);
    std::map<std::string, std::size_t> sent;  // model id -> index, awaiting acknowledgement
    absl::Status read_error;
    // Acknowledgements arrive on their own thread while this one sends.
    std::thread reader([&] {
      v1::IngestAck ack;
      while (stream->Read(&ack)) {
        auto it = sent.end();
        {
          absl::MutexLock lock(&sent_mutex_);
          it = sent.find(ack.model_id());
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
        absl::MutexLock lock(&sent_mutex_);
        if (acked[i]) continue;
      }
      const ModelToIngest& m = models[i];
      absl::StatusOr<TriangleMesh> mesh = ReadMesh(m.path, nullptr, limits);
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
      rpc::MeshToProto(*mesh, request.mutable_mesh()->mutable_mesh());
      {
        absl::MutexLock lock(&sent_mutex_);
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
    if (status.ok()) give_up = absl::Now() + absl::GetFlag(FLAGS_reconnect_for);
    absl::SleepFor(absl::Milliseconds(500));  // reconnect and send the rest
  }
  bar.Finish();
  std::fprintf(stderr, "ingest: %zu models acknowledged (%zu new)\n", models.size(), created);
  for (const std::string& job : jobs) {
    MESHSEEK_RETURN_IF_ERROR(WaitForJob(stub, job, "extract").status());
  }
  return absl::OkStatus();
}

// A collection that exists keeps its parameters (the parameter flags only
// say how to create one); flags that disagree with them are an error.
absl::Status EnsureCollection(v1::Coordinator::Stub* stub, const std::string& name) {
  v1::GetCollectionRequest get;
  get.set_name(name);
  v1::Collection existing;
  const absl::Status found = Call(stub, &v1::Coordinator::Stub::GetCollection, get, &existing);
  if (found.ok()) return CheckFlagsAgreeWith(existing.params(), name);
  if (!absl::IsNotFound(found)) return found;
  v1::CreateCollectionRequest create;
  create.set_name(name);
  MESHSEEK_ASSIGN_OR_RETURN(*create.mutable_params(), CollectionParamsFromFlags());
  v1::Collection collection;
  return Call(stub, &v1::Coordinator::Stub::CreateCollection, create, &collection);
}

absl::Status BuildCollection(v1::Coordinator::Stub* stub, const std::string& name) {
  v1::BuildRequest build;
  build.set_collection(name);
  v1::JobStatus job;
  MESHSEEK_RETURN_IF_ERROR(Call(stub, &v1::Coordinator::Stub::Build, build, &job));
  MESHSEEK_ASSIGN_OR_RETURN(const v1::JobStatus done, WaitForJob(stub, job.job_id(), "build"));
  std::fprintf(stderr, "build: %s\n", done.message().c_str());
  return absl::OkStatus();
}

std::string RequireCollection() { return absl::GetFlag(FLAGS_collection); }

}  // namespace

absl::Status RunIngest() {
  const std::string collection = RequireCollection();
  if (collection.empty()) return absl::InvalidArgumentError("ingest needs --collection NAME");
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ModelToIngest> models, ModelsFromFlags());
  MESHSEEK_ASSIGN_OR_RETURN(auto session, Session::Open());
  MESHSEEK_RETURN_IF_ERROR(EnsureCollection(session->stub(), collection));
  return IngestModels(session->stub(), collection, models);
}

absl::Status RunBuild() {
  const std::string collection = RequireCollection();
  if (collection.empty()) return absl::InvalidArgumentError("build needs --collection NAME");
  MESHSEEK_ASSIGN_OR_RETURN(auto session, Session::Open());
  return BuildCollection(session->stub(), collection);
}

absl::Status RunQuery(const std::string& model_path) {
  const std::string collection = RequireCollection();
  if (collection.empty()) return absl::InvalidArgumentError("query needs --collection NAME");
  if (model_path.empty()) return absl::InvalidArgumentError("query needs a mesh file: meshseek query MODEL");
  MESHSEEK_ASSIGN_OR_RETURN(const OutputFormat format, OutputFormatFromFlags());
  MESHSEEK_ASSIGN_OR_RETURN(const MeshReadOptions limits, rpc::MeshLimitsFromFlags());
  MESHSEEK_ASSIGN_OR_RETURN(const TriangleMesh mesh, ReadMesh(model_path, nullptr, limits));
  MESHSEEK_ASSIGN_OR_RETURN(auto session, Session::Open());
  v1::QueryRequest request;
  request.set_collection(collection);
  request.set_top_k(absl::GetFlag(FLAGS_top_k));
  request.set_candidates(absl::GetFlag(FLAGS_candidates));
  rpc::MeshToProto(mesh, request.mutable_mesh()->mutable_mesh());
  v1::QueryResponse response;
  MESHSEEK_RETURN_IF_ERROR(Call(session->stub(), &v1::Coordinator::Stub::Query, request, &response,
                                absl::Minutes(5)));
  if (format == OutputFormat::kJson) {
    std::printf("%s\n", ProtoToJson(response).c_str());
    return absl::OkStatus();
  }
  std::printf("%u features; nearest in '%s':\n", response.query_features(), collection.c_str());
  std::printf("%4s  %-24s %-16s %s\n", "rank", "model", "label", "distance");
  int rank = 0;
  for (const v1::ScoredModel& r : response.results()) {
    std::printf("%4d  %-24s %-16s %.6g\n", ++rank, r.model_id().c_str(), r.label().c_str(), r.distance());
  }
  return absl::OkStatus();
}

// Every failed model of `collection` and why, a page at a time.
absl::StatusOr<std::vector<v1::ModelInfo>> FailedModels(v1::Coordinator::Stub* stub,
                                                        const std::string& collection) {
  v1::ListCollectionModelsRequest list;
  list.set_collection(collection);
  list.set_state(v1::MODEL_STATE_FAILED);
  list.set_page_size(1000);
  std::vector<v1::ModelInfo> failed;
  while (true) {
    v1::ListCollectionModelsResponse page;
    MESHSEEK_RETURN_IF_ERROR(Call(stub, &v1::Coordinator::Stub::ListModels, list, &page));
    failed.insert(failed.end(), page.models().begin(), page.models().end());
    if (page.next_page_token().empty()) return failed;
    list.set_page_token(page.next_page_token());
  }
}

void PrintStatusText(const v1::Collection& info, const std::vector<v1::ModelInfo>& failed) {
  std::string params;
  for (const v1::ParamValue& v : info.params().values()) {
    absl::StrAppend(&params, params.empty() ? "" : " ", v.name(), "=", v.value());
  }
  if (params.empty()) params = info.params().ShortDebugString();  // a legacy collection
  std::printf(
      "collection %s: %llu models, %llu pending, %llu extracted, %llu failed, %llu indexed "
      "(%llu added since the build); index generation '%s'\nparams: %s\n",
      info.name().c_str(),
      static_cast<unsigned long long>(info.models()),
      static_cast<unsigned long long>(info.pending()),
      static_cast<unsigned long long>(info.extracted()),
      static_cast<unsigned long long>(info.failed()),
      static_cast<unsigned long long>(info.indexed()),
      static_cast<unsigned long long>(info.added_since_build()),
      info.codebook_id().c_str(),
      params.c_str());
  if (!failed.empty()) std::printf("failed models:\n");
  for (const v1::ModelInfo& m : failed) {
    std::printf("  %s (%u attempt%s): %s\n", m.model_id().c_str(), m.attempts(),
                m.attempts() == 1 ? "" : "s", m.error().c_str());
  }
}

absl::Status RunStatus() {
  MESHSEEK_ASSIGN_OR_RETURN(const OutputFormat format, OutputFormatFromFlags());
  MESHSEEK_ASSIGN_OR_RETURN(auto session, Session::Open());
  if (const std::string job = absl::GetFlag(FLAGS_job); !job.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(const v1::JobStatus status, WaitForJob(session->stub(), job, job));
    std::printf("%s\n", format == OutputFormat::kJson ? ProtoToJson(status).c_str()
                                                       : status.DebugString().c_str());
    return absl::OkStatus();
  }
  const std::string collection = RequireCollection();
  if (collection.empty()) return absl::InvalidArgumentError("status needs --collection NAME or --job ID");
  v1::GetCollectionRequest get;
  get.set_name(collection);
  v1::Collection info;
  MESHSEEK_RETURN_IF_ERROR(Call(session->stub(), &v1::Coordinator::Stub::GetCollection, get, &info));
  std::vector<v1::ModelInfo> failed;
  if (info.failed() > 0) {
    MESHSEEK_ASSIGN_OR_RETURN(failed, FailedModels(session->stub(), collection));
  }
  if (format == OutputFormat::kText) {
    PrintStatusText(info, failed);
    return absl::OkStatus();
  }
  // {"collection": Collection, "failed_models": [ModelInfo, ...]}
  std::string models;
  for (const v1::ModelInfo& m : failed) absl::StrAppend(&models, models.empty() ? "" : ",", ProtoToJson(m));
  std::printf("{\"collection\":%s,\"failed_models\":[%s]}\n", ProtoToJson(info).c_str(),
              models.c_str());
  return absl::OkStatus();
}

absl::Status RunServe() {
  rpc::BlockTerminationSignals();
  EmbeddedSecurity security;
  security.coordinator.tls.cert_file = absl::GetFlag(FLAGS_tls_cert);
  security.coordinator.tls.key_file = absl::GetFlag(FLAGS_tls_key);
  security.coordinator.tls.ca_file = absl::GetFlag(FLAGS_tls_ca);
  security.coordinator.token_file = absl::GetFlag(FLAGS_token_file);
  MESHSEEK_RETURN_IF_ERROR(security.coordinator.Validate());
  MESHSEEK_ASSIGN_OR_RETURN(const MeshReadOptions limits, rpc::MeshLimitsFromFlags());
  MESHSEEK_ASSIGN_OR_RETURN(auto stack,
                            EmbeddedStack::Start(absl::GetFlag(FLAGS_data_dir),
                                                 absl::GetFlag(FLAGS_threads),
                                                 PortOr(50051),
                                                 security,
                                                 limits,
                                                 absl::GetFlag(FLAGS_metrics_port)));
  std::printf("meshseek serving on %s (data in %s); Ctrl-C stops\n",
              stack->coordinator_address().c_str(), absl::GetFlag(FLAGS_data_dir).c_str());
  if (const int metrics = absl::GetFlag(FLAGS_metrics_port); metrics != 0) {
    std::printf("metrics on http://127.0.0.1:%d/metrics\n", metrics);
  }
  std::fflush(stdout);
  rpc::WaitForTerminationSignal();
  return absl::OkStatus();
}

bool EvalInProcess() { return absl::GetFlag(FLAGS_server) == "in-process"; }

absl::StatusOr<CollectionEvaluation> EvaluateThroughServices(
    const std::vector<ManifestEntry>& models,
    CollectionOptions* flags,
    const std::string& manifest_path) {
  const CollectionOptions& options = *flags;
  const auto start = absl::Now();
  MESHSEEK_ASSIGN_OR_RETURN(auto session, Session::Open());
  v1::Coordinator::Stub* stub = session->stub();
  std::string collection = absl::GetFlag(FLAGS_collection);
  if (collection.empty()) {
    // Named after the manifest's folder, the method and a hash of the
    // parameters, so that evaluating again reuses the extracted models.
    // The canonical parameters (every one of the collection, by name).
    v1::PipelineParams canonical;
    rpc::CollectionParamsToProto(options, &canonical);
    const std::string params = canonical.SerializeAsString();
    std::string folder = std::filesystem::absolute(manifest_path).parent_path().filename().string();
    for (char& c : folder) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
    }
    collection = absl::StrCat(
        folder.empty() ? "eval" : folder,
        "-",
        absl::StrReplaceAll(options.MethodName(), {{"+", "_"}}),
        "-",
        absl::Hex(Fnv1a64(params, kFnv1a64OffsetBasis) & 0xffffffffu, absl::kZeroPad8));
  }
  MESHSEEK_RETURN_IF_ERROR(EnsureCollection(stub, collection));
  std::vector<ModelToIngest> to_ingest;
  for (const ManifestEntry& e : models) {
    to_ingest.push_back(
        {e.id, e.label, e.path, absl::StrCat("model '", e.id, "' (manifest line ", e.line, ")")});
  }
  MESHSEEK_RETURN_IF_ERROR(IngestModels(stub, collection, to_ingest));
  CollectionEvaluation evaluation;
  evaluation.timings.extract_seconds = absl::ToDoubleSeconds(absl::Now() - start);
  v1::GetCollectionRequest get;
  get.set_name(collection);
  v1::Collection info;
  MESHSEEK_RETURN_IF_ERROR(Call(stub, &v1::Coordinator::Stub::GetCollection, get, &info));
  const auto build_start = absl::Now();
  // The paper's protocol: codebooks trained on every model evaluated, so
  // models added live since the last build mean a build too.
  if (info.codebook_id().empty() || info.indexed() != info.models() ||
      info.added_since_build() > 0) {
    MESHSEEK_RETURN_IF_ERROR(BuildCollection(stub, collection));
  }
  evaluation.timings.codebook_seconds = absl::ToDoubleSeconds(absl::Now() - build_start);
  const auto rank_start = absl::Now();
  std::map<std::string, std::size_t> position;
  for (std::size_t i = 0; i < models.size(); ++i) position[models[i].id] = i;
  const std::size_t n = models.size();
  evaluation.models = models;
  evaluation.distances.assign(n * n, 0.0f);
  // The collection's own methods (an existing one evaluated without flags
  // keeps those it was made with, whatever the default).
  MESHSEEK_ASSIGN_OR_RETURN(CollectionOptions stored,
                            rpc::CollectionOptionsFromParams(info.params()));
  stored.SetRunOptions(options.num_threads(), options.show_progress());
  *flags = stored;
  evaluation.methods.resize(stored.methods.size());
  for (std::size_t m = 0; m < stored.methods.size(); ++m) {
    MethodEvaluation& method = evaluation.methods[m];
    method.method = stored.methods[m].extractor.method;
    method.features_per_model.assign(n, 0);
    method.codebook_size = FeatureMethodInfoOf(method.method).kind == DescriptorKind::kGlobal
                               ? 0
                               : stored.methods[m].kmeans.num_centroids;
  }
  std::vector<std::string> row_ids;
  std::size_t rows = 0;
  MESHSEEK_RETURN_IF_ERROR(rpc::RetryTransient(
      [&]() -> absl::Status {
        grpc::ClientContext context;
        rpc::SetDeadline(&context, absl::Minutes(30));
        v1::EvaluateRequest request;
        request.set_collection(collection);
        auto reader = stub->Evaluate(&context, request);
        v1::EvaluateRow row;
        row_ids.clear();
        rows = 0;
        std::vector<std::pair<std::size_t, std::vector<float>>> pending;
        while (reader->Read(&row)) {
          auto it = position.find(row.model_id());
          if (it == position.end() || row.distances_size() != static_cast<int>(n)) {
            context.TryCancel();
            reader->Finish();
            return absl::FailedPreconditionError(absl::StrCat(
                "collection '", collection, "' holds model ", row.model_id(),
                " that is not in the manifest or has another size; use another --collection"));
          }
          row_ids.push_back(row.model_id());
          pending.emplace_back(it->second, std::vector<float>(row.distances().begin(), row.distances().end()));
          // One count per method (a row of a collection of one method may
          // carry only `features`).
          for (std::size_t m = 0; m < evaluation.methods.size(); ++m) {
            evaluation.methods[m].features_per_model[it->second] =
                m < static_cast<std::size_t>(row.method_features_size())
                    ? row.method_features(static_cast<int>(m))
                    : row.features();
          }
          ++rows;
        }
        MESHSEEK_RETURN_IF_ERROR(rpc::FromGrpcStatus(reader->Finish()));
        // Row r's columns are in the collection's order (row_ids).
        for (auto& [i, distances] : pending) {
          for (std::size_t c = 0; c < n; ++c) {
            evaluation.distances[i * n + position[row_ids[c]]] = distances[c];
          }
        }
        return absl::OkStatus();
      },
      ReconnectRetry()));
  if (rows != n) {
    return absl::FailedPreconditionError(absl::StrCat("collection '", collection, "' has ", rows,
                                                      " models, the manifest ", n));
  }
  for (MethodEvaluation& method : evaluation.methods) {
    for (std::size_t f : method.features_per_model) method.models_without_features += f == 0;
  }
  std::vector<std::string> labels;
  for (const ManifestEntry& m : models) labels.push_back(m.label);
  MESHSEEK_ASSIGN_OR_RETURN(evaluation.metrics,
                            EvaluateRetrieval(labels, evaluation.distances, stored.num_threads()));
  evaluation.timings.rank_seconds = absl::ToDoubleSeconds(absl::Now() - rank_start);
  evaluation.timings.total_seconds = absl::ToDoubleSeconds(absl::Now() - start);
  std::fprintf(stderr, "eval: collection '%s'\n", collection.c_str());
  return evaluation;
}

}  // namespace meshseek::cli
