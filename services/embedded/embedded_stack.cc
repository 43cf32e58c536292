#include "services/embedded/embedded_stack.h"

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "services/codebook/codebook_grpc.h"
#include "services/coordinator/coordinator_grpc.h"
#include "services/extract/extract_grpc.h"
#include "services/index/index_grpc.h"
#include "services/resample/resample_grpc.h"

namespace meshseek {

absl::StatusOr<std::unique_ptr<EmbeddedStack>> EmbeddedStack::Start(
    const std::string& data_dir,
    int threads,
    int coordinator_port,
    const EmbeddedSecurity& security,
    const MeshReadOptions& mesh_limits,
    int metrics_port) {
  std::unique_ptr<EmbeddedStack> stack(new EmbeddedStack());
  const int cores = ResolveThreadCount(threads);
  rpc::ServerOptions server;
  server.address = "127.0.0.1:0";
  server.grace_period = absl::Seconds(2);
  server.security.tls = security.internal;
  auto serve = [&](const char* name,
                   std::unique_ptr<grpc::Service> binding) -> absl::StatusOr<std::string> {
    stack->bindings_.push_back(std::move(binding));
    MESHSEEK_ASSIGN_OR_RETURN(auto started,
                              rpc::RpcServer::Start(name, {stack->bindings_.back().get()}, server));
    const std::string address = absl::StrCat("127.0.0.1:", started->port());
    stack->servers_.push_back(std::move(started));
    return address;
  };
  ExtractServiceOptions extract;
  extract.workers = cores;
  extract.mesh_limits = mesh_limits;
  stack->resample_ = std::make_unique<ResampleService>(mesh_limits);
  stack->extract_ = std::make_unique<ExtractService>(extract);
  CodebookServiceOptions codebook{data_dir + "/codebook", cores};
  MESHSEEK_ASSIGN_OR_RETURN(stack->codebook_, CodebookService::Create(codebook));
  IndexServiceOptions index{data_dir + "/index", cores};
  MESHSEEK_ASSIGN_OR_RETURN(stack->index_, IndexService::Create(index));

  CoordinatorOptions coordinator;
  coordinator.data_dir = data_dir + "/coordinator";
  MESHSEEK_ASSIGN_OR_RETURN(
      coordinator.resample_target,
      serve("resample", std::make_unique<ResampleGrpc>(stack->resample_.get())));
  MESHSEEK_ASSIGN_OR_RETURN(
      coordinator.extract_target,
      serve("extract", std::make_unique<ExtractGrpc>(stack->extract_.get())));
  MESHSEEK_ASSIGN_OR_RETURN(
      coordinator.codebook_target,
      serve("codebook", std::make_unique<CodebookGrpc>(stack->codebook_.get())));
  MESHSEEK_ASSIGN_OR_RETURN(
      coordinator.index_target,
      serve("index", std::make_unique<IndexGrpc>(stack->index_.get())));
  coordinator.max_in_flight = cores;
  coordinator.mesh_limits = mesh_limits;
  rpc::ClientSecurityOptions outbound;
  outbound.tls = security.internal;
  MESHSEEK_ASSIGN_OR_RETURN(coordinator.service_credentials, rpc::MakeChannelCredentials(outbound));
  MESHSEEK_ASSIGN_OR_RETURN(stack->coordinator_, CoordinatorService::Create(coordinator));
  server.address = absl::StrCat("127.0.0.1:", coordinator_port);
  server.security = security.coordinator;
  // The process has one registry: the endpoint on the coordinator's server
  // serves the other four's calls as well.
  if (metrics_port != 0) server.metrics_address = absl::StrCat("127.0.0.1:", metrics_port);
  MESHSEEK_ASSIGN_OR_RETURN(
      stack->coordinator_address_,
      serve("coordinator", std::make_unique<CoordinatorGrpc>(stack->coordinator_.get())));
  return stack;
}

EmbeddedStack::~EmbeddedStack() {
  // The coordinator first (it calls the others), then its background work.
  if (!servers_.empty()) servers_.back()->Shutdown();
  if (coordinator_) coordinator_->Stop();
  for (auto& server : servers_) server->Shutdown();
}

}  // namespace meshseek
