// meshseek-coordinator: the API of meshseek (collections, ingest, build,
// query, evaluation), orchestrating the worker and state services. Flags:
// --data_dir, the four service targets, the work limits, --token_file (bearer
// token of the public API), the TLS flags of the channels to the services
// (--service_tls_*), the ranking graph (--exact_graph_models,
// --graph_candidates, --query_candidates), and the server flags (common/rpc/server_main.h).
#include <algorithm>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "common/rpc/client.h"
#include "common/rpc/credentials.h"
#include "common/flags/mesh_limit_flags.h"
#include "common/rpc/server_main.h"
#include "services/coordinator/coordinator_grpc.h"

namespace {
const meshseek::CoordinatorOptions kDefaults;
}

ABSL_FLAG(std::string, data_dir, "", "folder of the coordinator database (required)");
ABSL_FLAG(std::string, resample, "", "gRPC target of the resample workers, e.g. dns:///resample:50051");
ABSL_FLAG(std::string, extract, "", "gRPC target of the extract workers, e.g. dns:///extract:50051");
ABSL_FLAG(std::string, codebook, "", "gRPC target of the codebook service");
ABSL_FLAG(std::string, index, "", "gRPC target of the index service");
ABSL_FLAG(int, max_in_flight, kDefaults.max_in_flight,
          "models extracted at once over all workers (about the workers' total cores)");
ABSL_FLAG(int, max_pending, kDefaults.max_pending,
          "ingest acknowledgements wait while this many models wait for extraction");
ABSL_FLAG(absl::Duration, extract_deadline, kDefaults.extract_deadline,
          "deadline of one extraction or resampling call");
ABSL_FLAG(absl::Duration, call_deadline, kDefaults.call_deadline,
          "deadline of every other call to a service");
ABSL_FLAG(int, call_attempts, kDefaults.call_attempts,
          "tries of a call that fails transiently (backoff 0.1 s doubling to 5 s)");
ABSL_FLAG(int, model_attempts, kDefaults.model_attempts,
          "extraction attempts of a model failing with a non-permanent error before it is FAILED");
ABSL_FLAG(absl::Duration, retry_backoff, kDefaults.retry_backoff,
          "wait before a model's next extraction attempt, doubled after each");
ABSL_FLAG(absl::Duration, max_retry_backoff, kDefaults.max_retry_backoff,
          "longest wait between a model's extraction attempts");

ABSL_FLAG(int64_t, exact_graph_models,
          static_cast<int64_t>(kDefaults.ranking_graph.exact_graph_models),
          "a re-ranked collection's neighbour graph from all pairs up to this many models, from "
          "candidates above");
ABSL_FLAG(uint32_t, graph_candidates, kDefaults.ranking_graph.graph_candidates,
          "candidates per method of each model's list in an approximate neighbour graph");
ABSL_FLAG(uint32_t, query_candidates, kDefaults.ranking_graph.query_candidates,
          "candidates per method of a fused query that names none, on a collection past "
          "--exact_graph_models");
ABSL_FLAG(std::string, token_file, "",
          "file holding the bearer token every call but grpc.health.v1 must carry "
          "(UNAUTHENTICATED otherwise); needs --tls_cert/--tls_key");
ABSL_FLAG(std::string, service_tls_ca, "",
          "PEM CA bundle the services' certificates are verified against; turns TLS on "
          "for the channels to them");
ABSL_FLAG(std::string, service_tls_cert, "",
          "PEM client certificate presented to the services (mutual TLS)");
ABSL_FLAG(std::string, service_tls_key, "", "PEM private key of --service_tls_cert");
ABSL_FLAG(std::string, service_tls_name, "",
          "name the services' certificates carry, when not the targets' host names");

int main(int argc, char** argv) {
  meshseek::rpc::BlockTerminationSignals();
  absl::SetProgramUsageMessage("meshseek coordinator: collections, ingest, build, query, eval");
  absl::ParseCommandLine(argc, argv);
  meshseek::CoordinatorOptions options;
  options.data_dir = absl::GetFlag(FLAGS_data_dir);
  options.resample_target = absl::GetFlag(FLAGS_resample);
  options.extract_target = absl::GetFlag(FLAGS_extract);
  options.codebook_target = absl::GetFlag(FLAGS_codebook);
  options.index_target = absl::GetFlag(FLAGS_index);
  options.max_in_flight = absl::GetFlag(FLAGS_max_in_flight);
  options.max_pending = absl::GetFlag(FLAGS_max_pending);
  options.extract_deadline = absl::GetFlag(FLAGS_extract_deadline);
  options.call_deadline = absl::GetFlag(FLAGS_call_deadline);
  options.call_attempts = absl::GetFlag(FLAGS_call_attempts);
  options.model_attempts = absl::GetFlag(FLAGS_model_attempts);
  options.retry_backoff = absl::GetFlag(FLAGS_retry_backoff);
  options.max_retry_backoff = absl::GetFlag(FLAGS_max_retry_backoff);
  options.ranking_graph.exact_graph_models =
      static_cast<std::size_t>(std::max<int64_t>(0, absl::GetFlag(FLAGS_exact_graph_models)));
  options.ranking_graph.graph_candidates = absl::GetFlag(FLAGS_graph_candidates);
  options.ranking_graph.query_candidates = absl::GetFlag(FLAGS_query_candidates);
  auto limits = meshseek::flags::MeshLimitsFromFlags();
  if (!limits.ok()) return meshseek::rpc::ExitWithError("coordinator", limits.status());
  options.mesh_limits = *limits;
  meshseek::rpc::ClientSecurityOptions outbound;
  outbound.tls.ca_file = absl::GetFlag(FLAGS_service_tls_ca);
  outbound.tls.cert_file = absl::GetFlag(FLAGS_service_tls_cert);
  outbound.tls.key_file = absl::GetFlag(FLAGS_service_tls_key);
  outbound.server_name = absl::GetFlag(FLAGS_service_tls_name);
  auto credentials = meshseek::rpc::MakeChannelCredentials(outbound);
  if (!credentials.ok()) return meshseek::rpc::ExitWithError("coordinator", credentials.status());
  options.service_credentials = *credentials;
  options.service_tls_name = outbound.server_name;
  auto server = meshseek::rpc::ServerOptionsFromFlags();
  if (!server.ok()) return meshseek::rpc::ExitWithError("coordinator", server.status());
  server->security.token_file = absl::GetFlag(FLAGS_token_file);
  if (absl::Status valid = server->Validate(); !valid.ok()) {
    return meshseek::rpc::ExitWithError("coordinator", valid);
  }
  auto service = meshseek::CoordinatorService::Create(options);
  if (!service.ok()) return meshseek::rpc::ExitWithError("coordinator", service.status());
  meshseek::CoordinatorService* coordinator = service->get();
  meshseek::CoordinatorGrpc grpc(coordinator);
  return meshseek::rpc::ServeUntilSignal("coordinator", {&grpc}, *server,
                                         [coordinator] { coordinator->Stop(); });
}
