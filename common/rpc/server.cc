#include "common/rpc/server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/resource_quota.h>
#include <grpcpp/support/server_interceptor.h>
#include <signal.h>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "common/base/logging.h"

namespace meshseek::rpc {
namespace {

// At most `max_running` holders; the others wait in arrival order, each on
// its own server thread (a synchronous server has no other place to park a
// call). The queue's bound is not counted here: gRPC's thread cap
// (max_running + max_queued + 1) stops calls beyond it before they arrive.
// Every call waits its turn, even one that arrives with the queue full:
// gRPC then usually answers it RESOURCE_EXHAUSTED without running its
// handler, but not always (a thread still sending a finished call's status
// is counted in the cap while its slot is already free), and letting such a
// call through at once ran three handlers on a two-slot server (rpc/
// server_test, once its cases ran one per process). A refusal therefore
// waits for a slot too, and the running bound always holds.
class AdmissionGate {
 public:
  explicit AdmissionGate(int max_running) : max_running_(max_running) {}

  void Enter() {
    absl::MutexLock lock(&mutex_);
    const Turn turn{this, next_ticket_++};
    mutex_.Await(absl::Condition(&turn, &Turn::Ready));
    ++next_admitted_;
    ++running_;
  }

  void Leave() {
    absl::MutexLock lock(&mutex_);
    --running_;
  }

 private:
  // A waiting call's place in the queue: first come, first served.
  struct Turn {
    AdmissionGate* gate;
    uint64_t ticket;
    bool Ready() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(gate->mutex_) {
      return gate->running_ < gate->max_running_ && ticket == gate->next_admitted_;
    }
  };

  const int max_running_;
  absl::Mutex mutex_;
  int running_ ABSL_GUARDED_BY(mutex_) = 0;
  uint64_t next_ticket_ ABSL_GUARDED_BY(mutex_) = 0;
  uint64_t next_admitted_ ABSL_GUARDED_BY(mutex_) = 0;
};

// Takes a slot when a unary call's request has arrived (on the server thread
// that will run it) and gives it back when the status is sent, or when the
// call ends without one (cancelled).
class AdmissionInterceptor final : public grpc::experimental::Interceptor {
 public:
  explicit AdmissionInterceptor(AdmissionGate* gate) : gate_(gate) {}
  ~AdmissionInterceptor() override {
    if (holding_) gate_->Leave();
  }

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    using grpc::experimental::InterceptionHookPoints;
    if (!holding_ && !done_ &&
        methods->QueryInterceptionHookPoint(InterceptionHookPoints::POST_RECV_INITIAL_METADATA)) {
      gate_->Enter();
      holding_ = true;
    }
    if (holding_ && methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS)) {
      gate_->Leave();
      holding_ = false;
      done_ = true;
    }
    methods->Proceed();
  }

 private:
  AdmissionGate* const gate_;
  bool holding_ = false;
  bool done_ = false;
};

class AdmissionInterceptorFactory final
    : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit AdmissionInterceptorFactory(std::shared_ptr<AdmissionGate> gate)
      : gate_(std::move(gate)) {}

  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override {
    // Health checks must answer under load (a probe that queues behind work
    // gets the server restarted); streams may stay open for minutes and
    // would hold a slot all that time.
    if (info->type() != grpc::experimental::ServerRpcInfo::Type::UNARY ||
        absl::StartsWith(info->method(), "/grpc.health.v1.Health/")) {
      return nullptr;
    }
    return new AdmissionInterceptor(gate_.get());
  }

 private:
  std::shared_ptr<AdmissionGate> gate_;
};

// The port of host:port, or -1 when there is none.
int PortOf(const std::string& address) {
  const std::size_t colon = address.rfind(':');
  int port = -1;
  if (colon == std::string::npos || !absl::SimpleAtoi(address.substr(colon + 1), &port)) return -1;
  return port;
}

}  // namespace

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
  if (max_queued_calls < 0 || max_queued_calls > 8192) {
    return absl::InvalidArgumentError(
        absl::StrCat("queued calls must be in [0, 8192], got ", max_queued_calls));
  }
  if (!health_address.empty() && health_address.find(':') == std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("health address must be host:port, got '", health_address, "'"));
  }
  if (!metrics_address.empty()) {
    const int port = PortOf(metrics_address);
    if (port < 0 || port > 65535 || (port != 0 && port == PortOf(address))) {
      return absl::InvalidArgumentError(absl::StrCat(
          "metrics address must be host:port with a port other than the server's, got '",
          metrics_address,
          "'"));
    }
  }
  if (absl::Status secure = security.Validate(); !secure.ok()) return secure;
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
  if (!options.metrics_address.empty()) {
    absl::StatusOr<std::unique_ptr<MetricsEndpoint>> metrics =
        MetricsEndpoint::Start(options.metrics_address);
    if (!metrics.ok()) {
      return absl::Status(metrics.status().code(),
                          absl::StrCat(name, ": ", metrics.status().message()));
    }
    server->metrics_ = *std::move(metrics);
  }
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials =
      MakeServerCredentials(options.security);
  if (!credentials.ok()) {
    return absl::Status(credentials.status().code(),
                        absl::StrCat(name, ": ", credentials.status().message()));
  }
  builder.AddListeningPort(options.address, *credentials, &server->port_);
  // A port in use is refused: with gRPC's default SO_REUSEPORT a second
  // server would bind it too and silently take some of the first's calls.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  builder.SetMaxSendMessageSize(options.max_message_bytes);
  grpc::ResourceQuota quota(absl::StrCat("meshseek-", name));
  // The thread cap bounds running + queued calls; the gate below bounds the
  // running ones. The one thread more is the poller gRPC needs to accept the
  // next call (and to refuse it when every other thread is taken).
  quota.SetMaxThreads(options.max_threads + options.max_queued_calls + 1);
  builder.SetResourceQuota(quota);
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> interceptors;
  interceptors.push_back(MetricsInterceptorFactory(name));
  interceptors.push_back(std::make_unique<AdmissionInterceptorFactory>(
      std::make_shared<AdmissionGate>(options.max_threads)));
  builder.experimental().SetInterceptorCreators(std::move(interceptors));
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_MS,
                             static_cast<int>(absl::ToInt64Milliseconds(options.max_connection_age)));
  // No GRPC_ARG_MAX_CONNECTION_AGE_GRACE_MS: an aged connection takes no new
  // calls, and the calls on it run to their end however long they queue (a
  // grace of a few seconds killed queued and long calls with UNAVAILABLE
  // "enter idle" under load). Shutdown has its own grace period.
  for (grpc::Service* service : services) builder.RegisterService(service);
  server->server_ = builder.BuildAndStart();
  if (server->server_ == nullptr || server->port_ == 0) {
    return absl::UnavailableError(absl::StrCat(
        name, ": cannot listen on ", options.address,
        options.security.tls_enabled() ? " (port in use, or a bad TLS certificate or key?)"
                                       : " (port in use?)"));
  }
  if (!options.health_address.empty()) {
    // A server of its own: a second port on the main server would serve
    // every service in plaintext. Nothing is registered but the default
    // health service (reflection's plugin is process-wide and comes along;
    // it lists the public schemas but calls nothing).
    grpc::ServerBuilder health;
    health.AddListeningPort(options.health_address, grpc::InsecureServerCredentials(),
                            &server->health_port_);
    health.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
    server->health_server_ = health.BuildAndStart();
    if (server->health_server_ == nullptr || server->health_port_ == 0) {
      return absl::UnavailableError(absl::StrCat(
          name, ": cannot listen on health address ", options.health_address, " (port in use?)"));
    }
    server->health_server_->GetHealthCheckService()->SetServingStatus(true);
  }
  server->server_->GetHealthCheckService()->SetServingStatus(true);
  MESHSEEK_LOG(INFO)
      << name << ": serving on port " << server->port_
      << (options.security.tls_enabled() ? " (TLS" : " (plaintext")
      << (options.security.tls.ca_file.empty() ? "" : ", client certificates required")
      << (options.security.token_file.empty() ? "" : ", bearer token required") << ")"
      << (server->health_port_ != 0 ? absl::StrCat(", health on port ", server->health_port_)
                                    : std::string())
      << (server->metrics_ != nullptr ? absl::StrCat(", metrics on port ", server->metrics_->port())
                                      : std::string());
  return server;
}

RpcServer::~RpcServer() { Shutdown(); }

void RpcServer::Shutdown() {
  if (shut_down_ || server_ == nullptr) return;
  shut_down_ = true;
  MESHSEEK_LOG(INFO) << name_ << ": shutting down (grace "
                     << absl::FormatDuration(options_.grace_period) << ")";
  server_->GetHealthCheckService()->SetServingStatus(false);
  if (health_server_) health_server_->GetHealthCheckService()->SetServingStatus(false);
  server_->Shutdown(std::chrono::system_clock::now() +
                    absl::ToChronoMilliseconds(options_.grace_period));
  server_->Wait();
  if (health_server_) {
    health_server_->Shutdown(std::chrono::system_clock::now());
    health_server_->Wait();
  }
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
