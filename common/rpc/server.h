// Server bootstrap shared by every meshseek service, so that each has the
// same operational behaviour:
//   - the standard health service (grpc.health.v1) with real serving status:
//     SERVING once started, NOT_SERVING as soon as shutdown begins (load
//     balancers stop sending before the port closes);
//   - reflection, so grpcurl can list and call the services;
//   - explicit message-size limits (over-limit messages fail with
//     RESOURCE_EXHAUSTED naming the limit; the server keeps serving);
//   - bounded concurrency with a bounded queue (admission): at most
//     `max_threads` unary calls run at once; up to `max_queued_calls` more
//     wait, first come first served, on a thread of their own; a call beyond
//     both gets RESOURCE_EXHAUSTED (gRPC's "Server Threadpool Exhausted": the
//     thread cap below is what makes it) as soon as a slot frees. A burst of
//     64 calls to a 16-thread server is therefore served, not refused;
//   - TLS, mutual TLS and a bearer token (credentials.h, `security`), and an
//     optional plaintext port that serves only grpc.health.v1, for probes
//     that cannot speak TLS (kubelet's gRPC probes);
//   - a maximum connection age, so clients re-resolve DNS and find new
//     replicas;
//   - graceful shutdown: NOT_SERVING, stop taking calls, let in-flight calls
//     finish within the grace period, then cancel them;
//   - Prometheus metrics (metrics.h): every call counted by method and status
//     and timed, served over HTTP when `metrics_address` is set.
#ifndef MESHSEEK_COMMON_RPC_SERVER_H_
#define MESHSEEK_COMMON_RPC_SERVER_H_

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/rpc/credentials.h"
#include "common/rpc/metrics.h"

namespace meshseek::rpc {

struct ServerOptions {
  /// host:port to listen on; port 0 picks a free port (see RpcServer::port).
  std::string address = "0.0.0.0:0";
  /// Largest message received or sent. Meshes of a million triangles and a
  /// collection's worth of descriptor chunks fit in the default.
  int max_message_bytes = 64 << 20;
  /// Unary calls running at once (the worker pool bound). Streaming calls
  /// and health checks do not wait for a slot (a stream may stay open for
  /// minutes), but do take a thread of the cap below while open.
  int max_threads = 16;
  /// Unary calls that wait for a running slot when all are taken. Each holds
  /// a sleeping thread and its received request. gRPC's thread cap is set to
  /// max_threads + max_queued_calls + 2 (its pollers), so the queue is the
  /// bound: beyond it a call gets RESOURCE_EXHAUSTED when a slot frees (the
  /// refusal waits its turn, so that max_threads always holds).
  int max_queued_calls = 256;
  /// How long in-flight calls may run on after shutdown begins.
  absl::Duration grace_period = absl::Seconds(10);
  /// Connections take no new calls after this age (GOAWAY), so that clients
  /// re-resolve their targets and spread over new replicas; the calls in
  /// flight on them finish, however long they take.
  absl::Duration max_connection_age = absl::Seconds(30);
  /// TLS files and bearer token (credentials.h); default: plaintext, no token.
  ServerSecurityOptions security;
  /// host:port of a plaintext port that serves grpc.health.v1 only (and
  /// mirrors the main port's serving status); empty: none. Port 0 picks one.
  std::string health_address;
  /// host:port of a plaintext HTTP endpoint serving the process's Prometheus
  /// metrics at /metrics (metrics.h); empty: none. Calls are counted either
  /// way, into one registry per process, so one endpoint covers every server
  /// of the process (the embedded stack gives it to one of its five). Port 0
  /// picks a free port.
  std::string metrics_address;

  absl::Status Validate() const;
};

class RpcServer {
 public:
  /// Starts serving `services` (not owned; they must outlive the server).
  /// `name` is used in log lines. Unavailable when the address cannot be bound.
  static absl::StatusOr<std::unique_ptr<RpcServer>> Start(const std::string& name,
                                                          const std::vector<grpc::Service*>& services,
                                                          const ServerOptions& options);
  ~RpcServer();

  /// The bound port.
  int port() const { return port_; }
  /// The bound health-only port; 0 when there is none.
  int health_port() const { return health_port_; }
  /// The bound metrics port; 0 when there is none.
  int metrics_port() const { return metrics_ ? metrics_->port() : 0; }
  /// Graceful shutdown as described above; idempotent.
  void Shutdown();

 private:
  RpcServer() = default;
  std::string name_;
  ServerOptions options_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<grpc::Server> health_server_;
  std::unique_ptr<MetricsEndpoint> metrics_;
  int port_ = 0;
  int health_port_ = 0;
  bool shut_down_ = false;
};

// Blocks SIGTERM and SIGINT in the calling thread and in every thread it
// starts later; call first thing in main, before any server or thread starts,
// then WaitForTerminationSignal.
void BlockTerminationSignals();
// Waits for SIGTERM or SIGINT and returns its number.
int WaitForTerminationSignal();

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_SERVER_H_
