// Prometheus metrics of a meshseek process, one registry for the whole
// process, so that one HTTP endpoint covers every server in it (the embedded
// stack's five services as well as one service binary):
//   meshseek_rpc_calls_total{service, method, code}   counter, every call
//       served, streams and health checks included, by its gRPC status;
//   meshseek_rpc_duration_seconds{service, method}    histogram, from the
//       call's arrival (queueing for admission included) to its status;
//   gauges a service computes when scraped (ScrapeGauge below), e.g.
//       meshseek_coordinator_models{collection, state} and
//       meshseek_index_models{collection}.
// RpcServer counts every call (server.cc installs MetricsInterceptorFactory);
// ServerOptions::metrics_address serves them. The endpoint is plaintext HTTP
// without authentication, like every Prometheus exporter: it shows method
// names, status codes and collection names, nothing of the models.
#ifndef MESHSEEK_COMMON_RPC_METRICS_H_
#define MESHSEEK_COMMON_RPC_METRICS_H_

#include <grpcpp/support/server_interceptor.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"

namespace httplib {
class Server;
}

namespace meshseek::rpc {

/// One sample of a gauge computed at scrape time.
struct GaugeSample {
  std::map<std::string, std::string> labels;
  double value = 0;
};

/// A gauge family computed at each scrape by a callback, registered for as
/// long as this handle lives. Gauges of the same name are served as one
/// family, and samples with the same labels are summed (two index shards in
/// one process report their collections' total). The callback runs on the
/// endpoint's thread and must be cheap (one SQL aggregate, a walk over an
/// in-memory map); an error drops its samples from that scrape and is
/// logged. The destructor waits for a scrape in progress, so the callback may
/// use whatever the owner of the handle destroys after it.
class ScrapeGauge {
 public:
  using Collect = std::function<absl::StatusOr<std::vector<GaugeSample>>()>;
  static std::unique_ptr<ScrapeGauge> Register(const std::string& name,
                                               const std::string& help,
                                               Collect collect);
  ~ScrapeGauge();
  ScrapeGauge(const ScrapeGauge&) = delete;
  ScrapeGauge& operator=(const ScrapeGauge&) = delete;

 private:
  explicit ScrapeGauge(uint64_t id) : id_(id) {}
  const uint64_t id_;
};

/// Serves the process's metrics at http://ADDRESS/metrics (Prometheus text
/// format) until destroyed. cpp-httplib, as the web gateway: its threads have
/// the default stack (civetweb's, behind prometheus-cpp's own exposer, are
/// too small for a scrape under AddressSanitizer).
class MetricsEndpoint {
 public:
  /// `address`: host:port; port 0 picks a free one. Unavailable when it
  /// cannot be bound.
  static absl::StatusOr<std::unique_ptr<MetricsEndpoint>> Start(const std::string& address);
  ~MetricsEndpoint();

  int port() const { return port_; }

 private:
  MetricsEndpoint() = default;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
};

/// Counts and times every call of a server as `service` (the label).
std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> MetricsInterceptorFactory(
    const std::string& service);

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_METRICS_H_
