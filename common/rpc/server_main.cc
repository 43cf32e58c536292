#include "common/rpc/server_main.h"

#include <iostream>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "common/base/logging.h"

ABSL_FLAG(std::string, host, "0.0.0.0", "address to listen on");
ABSL_FLAG(int, port, 0, "port to listen on (0: any free port, printed at start)");
ABSL_FLAG(int, max_message_mb, 64, "largest gRPC message received or sent, MiB");
ABSL_FLAG(int, server_threads, 16, "unary calls served at once (bounded worker pool)");
ABSL_FLAG(int, max_queued_calls, 256,
          "unary calls that wait for a server thread beyond --server_threads; "
          "beyond both a call gets RESOURCE_EXHAUSTED");
ABSL_FLAG(std::string, tls_cert, "",
          "PEM certificate chain this server presents; with --tls_key turns TLS on (plaintext refused)");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(std::string, tls_ca, "",
          "PEM CA bundle: require client certificates signed by it (mutual TLS; needs --tls_cert)");
ABSL_FLAG(int, health_port, 0,
          "also serve grpc.health.v1 alone in plaintext on this port, for probes that cannot "
          "speak TLS (kubelet gRPC probes); 0: none");
ABSL_FLAG(int,
          metrics_port,
          0,
          "serve Prometheus metrics (plaintext HTTP, /metrics) on this port of --host; 0: none");
ABSL_FLAG(absl::Duration,
          grace_period,
          absl::Seconds(10),
          "on SIGTERM: how long in-flight calls may finish before they are cancelled");
ABSL_FLAG(absl::Duration,
          max_connection_age,
          absl::Seconds(30),
          "connections are recycled after this age so clients re-resolve and find new replicas");

namespace meshseek::rpc {

absl::StatusOr<ServerOptions> ServerOptionsFromFlags() {
  ServerOptions options;
  const int port = absl::GetFlag(FLAGS_port);
  if (port < 0 || port > 65535) {
    return absl::InvalidArgumentError(absl::StrCat("--port must be in [0, 65535], got ", port));
  }
  const std::string host = absl::GetFlag(FLAGS_host);
  options.address = host.find(':') != std::string::npos ? absl::StrCat("[", host, "]:", port)
                                                        : absl::StrCat(host, ":", port);
  const int mb = absl::GetFlag(FLAGS_max_message_mb);
  if (mb < 1 || mb > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("--max_message_mb must be in [1, 1024], got ", mb));
  }
  options.max_message_bytes = mb << 20;
  options.max_threads = absl::GetFlag(FLAGS_server_threads);
  options.max_queued_calls = absl::GetFlag(FLAGS_max_queued_calls);
  options.security.tls.cert_file = absl::GetFlag(FLAGS_tls_cert);
  options.security.tls.key_file = absl::GetFlag(FLAGS_tls_key);
  options.security.tls.ca_file = absl::GetFlag(FLAGS_tls_ca);
  const int health_port = absl::GetFlag(FLAGS_health_port);
  if (health_port < 0 || health_port > 65535 || (health_port != 0 && health_port == port)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--health_port must be in [1, 65535] and differ from --port (0: none), got ", health_port));
  }
  if (health_port != 0) {
    options.health_address = host.find(':') != std::string::npos
                                 ? absl::StrCat("[", host, "]:", health_port)
                                 : absl::StrCat(host, ":", health_port);
  }
  const int metrics_port = absl::GetFlag(FLAGS_metrics_port);
  if (metrics_port < 0 || metrics_port > 65535 ||
      (metrics_port != 0 && (metrics_port == port || metrics_port == health_port))) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--metrics_port must be in [1, 65535] and differ from --port and --health_port (0: none), "
        "got ",
        metrics_port));
  }
  if (metrics_port != 0) {
    options.metrics_address = host.find(':') != std::string::npos
                                  ? absl::StrCat("[", host, "]:", metrics_port)
                                  : absl::StrCat(host, ":", metrics_port);
  }
  options.grace_period = absl::GetFlag(FLAGS_grace_period);
  options.max_connection_age = absl::GetFlag(FLAGS_max_connection_age);
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  return options;
}

int ExitWithError(const std::string& name, const absl::Status& status) {
  std::cerr << name << ": " << status << "\n";
  return 2;
}

int ServeUntilSignal(const std::string& name,
                     const std::vector<grpc::Service*>& services,
                     const std::function<void()>& on_stop) {
  absl::StatusOr<ServerOptions> options = ServerOptionsFromFlags();
  if (!options.ok()) return ExitWithError(name, options.status());
  return ServeUntilSignal(name, services, *options, on_stop);
}

int ServeUntilSignal(const std::string& name,
                     const std::vector<grpc::Service*>& services,
                     const ServerOptions& options,
                     const std::function<void()>& on_stop) {
  absl::StatusOr<std::unique_ptr<RpcServer>> server = RpcServer::Start(name, services, options);
  if (!server.ok()) return ExitWithError(name, server.status());
  // One line on stdout that scripts can wait for.
  std::cout << name << " listening on port " << (*server)->port() << std::endl;
  const int signal = WaitForTerminationSignal();
  MESHSEEK_LOG(INFO) << name << ": signal " << signal;
  (*server)->Shutdown();
  if (on_stop) on_stop();
  return 0;
}

}  // namespace meshseek::rpc
