// The gRPC client commands: ingest, build, query, status, serve. Without
// --server each command starts the embedded stack on --data_dir for its
// duration (coordinator_client.h).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli/commands.h"
#include "cli/coordinator_client.h"
#include "cli/output_format.h"
#include "common/base/status_macros.h"
#include "common/base/file_io.h"
#include "common/geometry/mesh_io.h"
#include "common/global/picture_silhouette.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/rpc/server.h"
#include "common/wire/convert.h"
#include "meshseek/v1/coordinator.grpc.pb.h"
#include "services/embedded/embedded_stack.h"

namespace meshseek::cli {
namespace {

// The models of --manifest or --folder.
absl::StatusOr<std::vector<ModelToIngest>> ModelsToIngest(const CliFlags& flags) {
  std::vector<ModelToIngest> models;
  const std::string& manifest = flags.manifest;
  const std::string& folder = flags.folder;
  if (!manifest.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ManifestEntry> entries, ReadManifest(manifest));
    models = ModelsOfManifest(entries);
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

}  // namespace

absl::Status RunIngest(const CliFlags& flags) {
  if (flags.collection.empty()) return absl::InvalidArgumentError("ingest needs --collection NAME");
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ModelToIngest> models, ModelsToIngest(flags));
  MESHSEEK_ASSIGN_OR_RETURN(auto client, CoordinatorClient::Open(flags.client));
  MESHSEEK_RETURN_IF_ERROR(client->EnsureCollection(flags.collection, flags.params));
  return client->Ingest(flags.collection, models);
}

absl::Status RunBuild(const CliFlags& flags) {
  if (flags.collection.empty()) return absl::InvalidArgumentError("build needs --collection NAME");
  MESHSEEK_ASSIGN_OR_RETURN(auto client, CoordinatorClient::Open(flags.client));
  return client->Build(flags.collection);
}

namespace {

// The query's answer from the coordinator: by mesh (QueryRequest) or by
// picture (QueryByImageRequest, --image).
absl::StatusOr<v1::QueryResponse> AskQuery(const CliFlags& flags, const std::string& model_path) {
  if (model_path.empty() == flags.image.empty()) {
    return absl::InvalidArgumentError(
        "query needs a mesh file or a picture, one of them: meshseek query MODEL, or "
        "meshseek query --image PICTURE");
  }
  v1::QueryResponse response;
  if (!flags.image.empty()) {
    v1::QueryByImageRequest request;
    request.set_collection(flags.collection);
    request.set_top_k(flags.top_k);
    MESHSEEK_ASSIGN_OR_RETURN(*request.mutable_image(),
                              ReadFileToString(flags.image, kMaxPictureFileBytes));
    MESHSEEK_ASSIGN_OR_RETURN(auto client, CoordinatorClient::Open(flags.client));
    MESHSEEK_RETURN_IF_ERROR(client->Call(&v1::Coordinator::Stub::QueryByImage, request,
                                          &response, absl::Minutes(1)));
    return response;
  }
  MESHSEEK_ASSIGN_OR_RETURN(const TriangleMesh mesh,
                            ReadMesh(model_path, nullptr, flags.client.mesh_limits));
  MESHSEEK_ASSIGN_OR_RETURN(auto client, CoordinatorClient::Open(flags.client));
  v1::QueryRequest request;
  request.set_collection(flags.collection);
  request.set_top_k(flags.top_k);
  request.set_candidates(flags.candidates);
  wire::MeshToProto(mesh, request.mutable_mesh()->mutable_mesh());
  MESHSEEK_RETURN_IF_ERROR(
      client->Call(&v1::Coordinator::Stub::Query, request, &response, absl::Minutes(5)));
  return response;
}

}  // namespace

absl::Status RunQuery(const CliFlags& flags, const std::string& model_path) {
  if (flags.collection.empty()) return absl::InvalidArgumentError("query needs --collection NAME");
  MESHSEEK_ASSIGN_OR_RETURN(const v1::QueryResponse response, AskQuery(flags, model_path));
  if (flags.format == OutputFormat::kJson) {
    std::printf("%s\n", ProtoToJson(response).c_str());
    return absl::OkStatus();
  }
  if (flags.image.empty()) {
    std::printf("%u features; nearest in '%s':\n", response.query_features(),
                flags.collection.c_str());
  } else {
    std::printf("nearest in '%s' to the picture:\n", flags.collection.c_str());
  }
  std::printf("%4s  %-24s %-16s %s\n", "rank", "model", "label", "distance");
  int rank = 0;
  for (const v1::ScoredModel& r : response.results()) {
    std::printf("%4d  %-24s %-16s %.6g\n", ++rank, r.model_id().c_str(), r.label().c_str(), r.distance());
  }
  const v1::QueryTimings& t = response.timings();
  if (!flags.image.empty()) {
    std::printf("coordinator: picture %.0f ms, silhouette and view %.0f ms, search %.0f ms\n",
                1e3 * t.mesh_seconds(), 1e3 * t.signatures_seconds(), 1e3 * t.search_seconds());
    return absl::OkStatus();
  }
  std::string methods;
  for (const v1::MethodTiming& m : t.methods()) {
    absl::StrAppendFormat(&methods, "%s%s %.0f + %.0f", methods.empty() ? "" : ", ", m.method(),
                          1e3 * m.extract_seconds(), 1e3 * m.encode_seconds());
  }
  std::printf("coordinator: mesh %.0f ms, extract + encode %.0f ms (%s), search %.0f ms\n",
              1e3 * t.mesh_seconds(), 1e3 * t.signatures_seconds(), methods.c_str(),
              1e3 * t.search_seconds());
  return absl::OkStatus();
}

namespace {

// The collection's parameters as one line, "method=... vocabulary=...".
std::string ParamsLine(const v1::PipelineParams& params) {
  std::string line;
  for (const v1::ParamValue& v : params.values()) {
    absl::StrAppend(&line, line.empty() ? "" : " ", v.name(), "=", v.value());
  }
  return line.empty() ? params.ShortDebugString() : line;  // a legacy collection
}

void PrintStatusText(const v1::Collection& info, const std::vector<v1::ModelInfo>& failed) {
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
      ParamsLine(info.params()).c_str());
  if (!failed.empty()) std::printf("failed models:\n");
  for (const v1::ModelInfo& m : failed) {
    std::printf("  %s (%u attempt%s): %s\n", m.model_id().c_str(), m.attempts(),
                m.attempts() == 1 ? "" : "s", m.error().c_str());
  }
}

// `meshseek status` naming nothing: every collection, one line each.
absl::Status ListCollections(CoordinatorClient& client, OutputFormat format) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<v1::Collection> collections,
                            client.ListCollections());
  if (format == OutputFormat::kJson) {
    v1::ListCollectionsResponse list;  // {"collections": [Collection, ...]}
    for (const v1::Collection& c : collections) *list.add_collections() = c;
    std::printf("%s\n", ProtoToJson(list).c_str());
    return absl::OkStatus();
  }
  if (collections.empty()) {
    std::printf("no collections yet: meshseek ingest --collection NAME --manifest FILE\n");
    return absl::OkStatus();
  }
  std::printf("%-32s %8s %8s %7s  %s\n", "collection", "models", "indexed", "failed", "method");
  for (const v1::Collection& c : collections) {
    std::string method = "?";
    for (const v1::ParamValue& v : c.params().values()) {
      if (v.name() == "method") method = v.value();
    }
    std::printf("%-32s %8llu %8llu %7llu  %s\n", c.name().c_str(),
                static_cast<unsigned long long>(c.models()),
                static_cast<unsigned long long>(c.indexed()),
                static_cast<unsigned long long>(c.failed()), method.c_str());
  }
  std::printf("details: meshseek status --collection NAME\n");
  return absl::OkStatus();
}

}  // namespace

absl::Status RunStatus(const CliFlags& flags) {
  MESHSEEK_ASSIGN_OR_RETURN(auto client, CoordinatorClient::Open(flags.client));
  const bool json = flags.format == OutputFormat::kJson;
  if (!flags.job.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(const v1::JobStatus status, client->WaitForJob(flags.job, flags.job));
    std::printf("%s\n", json ? ProtoToJson(status).c_str() : status.DebugString().c_str());
    return absl::OkStatus();
  }
  if (flags.collection.empty()) return ListCollections(*client, flags.format);
  MESHSEEK_ASSIGN_OR_RETURN(const v1::Collection info, client->GetCollection(flags.collection));
  std::vector<v1::ModelInfo> failed;
  if (info.failed() > 0) {
    MESHSEEK_ASSIGN_OR_RETURN(failed, client->FailedModels(flags.collection));
  }
  if (!json) {
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

absl::Status RunServe(const CliFlags& flags) {
  rpc::BlockTerminationSignals();
  EmbeddedSecurity security;
  security.coordinator.tls = flags.client.security.tls;
  security.coordinator.token_file = flags.client.security.token_file;
  MESHSEEK_RETURN_IF_ERROR(security.coordinator.Validate());
  MESHSEEK_ASSIGN_OR_RETURN(auto stack,
                            EmbeddedStack::Start(flags.client.data_dir,
                                                 flags.client.threads,
                                                 flags.PortOr(50051),
                                                 security,
                                                 flags.client.mesh_limits,
                                                 flags.metrics_port));
  std::printf("meshseek serving on %s (data in %s); Ctrl-C stops\n",
              stack->coordinator_address().c_str(), flags.client.data_dir.c_str());
  if (flags.metrics_port != 0) {
    std::printf("metrics on http://127.0.0.1:%d/metrics\n", flags.metrics_port);
  }
  std::fflush(stdout);
  rpc::WaitForTerminationSignal();
  return absl::OkStatus();
}

}  // namespace meshseek::cli
