#include "common/rpc/server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/resource_quota.h>
#include <signal.h>

#include "absl/strings/str_cat.h"
#include "common/base/logging.h"

namespace meshseek::rpc {

absl::Status ServerOptions::Validate() const {
  if (address.empty() || address.find(':') == std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("server address must be host:port, got '", address, "'"));
  }
  if (max_message_bytes < (1 << 20)) {
    return absl::InvalidArgumentError(
        absl::StrCat("max message size must be at least 1 MiB, got ", max_message_bytes));
  }
  if (max_threads < 2 || max_threads > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("server threads must be in [2, 1024], got ", max_threads));
  }
  if (grace_period < absl::ZeroDuration() || max_connection_age < absl::Seconds(1)) {
    return absl::InvalidArgumentError("grace period must be >= 0 and connection age >= 1 s");
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<RpcServer>> RpcServer::Start(
    const std::string& name,
    const std::vector<grpc::Service*>& services,
    const ServerOptions& options) {
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  std::unique_ptr<RpcServer> server(new RpcServer());
  server->name_ = name;
  server->options_ = options;
  builder.AddListeningPort(options.address, grpc::InsecureServerCredentials(), &server->port_);
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  builder.SetMaxSendMessageSize(options.max_message_bytes);
  grpc::ResourceQuota quota(absl::StrCat("meshseek-", name));
  quota.SetMaxThreads(options.max_threads);
  builder.SetResourceQuota(quota);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_MS,
                             static_cast<int>(absl::ToInt64Milliseconds(options.max_connection_age)));
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_GRACE_MS,
                             static_cast<int>(absl::ToInt64Milliseconds(options.grace_period)));
  for (grpc::Service* service : services) builder.RegisterService(service);
  server->server_ = builder.BuildAndStart();
  if (server->server_ == nullptr || server->port_ == 0) {
    return absl::UnavailableError(
        absl::StrCat(name, ": cannot listen on ", options.address, " (port in use?)"));
  }
  server->server_->GetHealthCheckService()->SetServingStatus(true);
  MESHSEEK_LOG(INFO) << name << ": serving on port " << server->port_;
  return server;
}

RpcServer::~RpcServer() { Shutdown(); }

void RpcServer::Shutdown() {
  if (shut_down_ || server_ == nullptr) return;
  shut_down_ = true;
  MESHSEEK_LOG(INFO) << name_ << ": shutting down (grace "
                     << absl::FormatDuration(options_.grace_period) << ")";
  server_->GetHealthCheckService()->SetServingStatus(false);
  server_->Shutdown(std::chrono::system_clock::now() +
                    absl::ToChronoMilliseconds(options_.grace_period));
  server_->Wait();
}

void BlockTerminationSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
}

int WaitForTerminationSignal() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  int signal = 0;
  sigwait(&set, &signal);
  return signal;
}

}  // namespace meshseek::rpc
