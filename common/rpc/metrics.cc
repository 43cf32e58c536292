#include "common/rpc/metrics.h"

#include <google/protobuf/descriptor.h>
#include <httplib.h>
#include <prometheus/collectable.h>
#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/histogram.h>
#include <prometheus/metric_family.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>

#include <chrono>
#include <exception>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "absl/synchronization/mutex.h"
#include "common/base/logging.h"
#include "common/rpc/http_server.h"

namespace meshseek::rpc {
namespace {

// From a health check (about a millisecond) to a long ingest stream or build
// call (minutes): roughly 1-2.5-5 per decade, then minutes.
const prometheus::Histogram::BucketBoundaries& DurationBuckets() {
  // clang-format off
  static const auto* const buckets = new prometheus::Histogram::BucketBoundaries{
      0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5,
      1, 2.5, 5, 10, 30, 60, 120, 300, 600};
  // clang-format on
  return *buckets;
}

// The registry of the process's counters and histograms, plus the gauges
// computed at scrape time; the endpoint serves both as one Collectable.
class ProcessMetrics final : public prometheus::Collectable {
 public:
  ProcessMetrics()
      : registry_(std::make_shared<prometheus::Registry>()),
        calls_(prometheus::BuildCounter()
                   .Name("meshseek_rpc_calls_total")
                   .Help("RPCs served, by service, method and gRPC status code")
                   .Register(*registry_)),
        durations_(prometheus::BuildHistogram()
                       .Name("meshseek_rpc_duration_seconds")
                       .Help("RPC latency from arrival (admission queueing included) to status")
                       .Register(*registry_)) {}

  prometheus::Family<prometheus::Counter>& calls() { return calls_; }
  prometheus::Family<prometheus::Histogram>& durations() { return durations_; }

  uint64_t AddGauge(const std::string& name,
                    const std::string& help,
                    ScrapeGauge::Collect collect) {
    absl::MutexLock lock(&mutex_);
    const uint64_t id = next_id_++;
    gauges_.emplace(id, Gauge{name, help, std::move(collect)});
    return id;
  }
  void RemoveGauge(uint64_t id) {
    absl::MutexLock lock(&mutex_);
    gauges_.erase(id);
  }

  std::vector<prometheus::MetricFamily> Collect() const override {
    std::vector<prometheus::MetricFamily> families = registry_->Collect();
    struct Merged {
      std::string help;
      std::map<std::map<std::string, std::string>, double> values;
    };
    std::map<std::string, Merged> merged;
    {
      // Held while the callbacks run: RemoveGauge waits for them.
      absl::MutexLock lock(&mutex_);
      for (const auto& [id, gauge] : gauges_) {
        absl::StatusOr<std::vector<GaugeSample>> samples = gauge.collect();
        if (!samples.ok()) {
          MESHSEEK_LOG(WARNING) << "metrics: " << gauge.name << ": " << samples.status();
          continue;
        }
        Merged& family = merged[gauge.name];
        family.help = gauge.help;
        for (const GaugeSample& sample : *samples) family.values[sample.labels] += sample.value;
      }
    }
    for (const auto& [name, gauge] : merged) {
      prometheus::MetricFamily family;
      family.name = name;
      family.help = gauge.help;
      family.type = prometheus::MetricType::Gauge;
      for (const auto& [labels, value] : gauge.values) {
        prometheus::ClientMetric metric;
        for (const auto& [label, label_value] : labels)
          metric.label.push_back({label, label_value});
        metric.gauge.value = value;
        family.metric.push_back(std::move(metric));
      }
      families.push_back(std::move(family));
    }
    return families;
  }

 private:
  struct Gauge {
    std::string name;
    std::string help;
    ScrapeGauge::Collect collect;
  };

  const std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Family<prometheus::Counter>& calls_;
  prometheus::Family<prometheus::Histogram>& durations_;
  mutable absl::Mutex mutex_;
  uint64_t next_id_ ABSL_GUARDED_BY(mutex_) = 0;
  std::map<uint64_t, Gauge> gauges_ ABSL_GUARDED_BY(mutex_);
};

// Never destroyed: endpoints and servers may outlive static destruction.
const std::shared_ptr<ProcessMetrics>& Process() {
  static const auto* const metrics =
      new std::shared_ptr<ProcessMetrics>(std::make_shared<ProcessMetrics>());
  return *metrics;
}

// The method's label: its path when one of this binary's services or the
// health service defines it, else "unknown", so that clients calling made-up
// method names cannot grow the label set without bound.
std::string MethodLabel(const char* path) {
  const std::string method = path == nullptr ? "" : path;
  if (absl::StartsWith(method, "/grpc.health.v1.Health/")) return method;
  if (method.size() > 1 && method[0] == '/' &&
      google::protobuf::DescriptorPool::generated_pool()->FindMethodByName(
          absl::StrReplaceAll(method.substr(1), {{"/", "."}})) != nullptr) {
    return method;
  }
  return "unknown";
}

// What one method of one server records to.
struct MethodMetrics {
  std::string service;
  std::string method;
  prometheus::Histogram* duration = nullptr;
};

// Times one call from its creation (when it arrives) to its status.
class MetricsInterceptor final : public grpc::experimental::Interceptor {
 public:
  explicit MetricsInterceptor(const MethodMetrics* method)
      : method_(method), start_(std::chrono::steady_clock::now()) {}
  // A call that ends without sending a status was cancelled (its client went
  // away or its deadline passed).
  ~MetricsInterceptor() override {
    if (!recorded_) Record(grpc::StatusCode::CANCELLED);
  }

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (!recorded_ && methods->QueryInterceptionHookPoint(
                          grpc::experimental::InterceptionHookPoints::PRE_SEND_STATUS)) {
      Record(methods->GetSendStatus().error_code());
    }
    methods->Proceed();
  }

 private:
  void Record(grpc::StatusCode code) {
    recorded_ = true;
    const std::chrono::duration<double> seconds = std::chrono::steady_clock::now() - start_;
    method_->duration->Observe(seconds.count());
    Process()
        ->calls()
        .Add({{"service", method_->service},
              {"method", method_->method},
              {"code", absl::StatusCodeToString(static_cast<absl::StatusCode>(code))}})
        .Increment();
  }

  const MethodMetrics* const method_;
  const std::chrono::steady_clock::time_point start_;
  bool recorded_ = false;
};

class MetricsFactory final : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit MetricsFactory(std::string service) : service_(std::move(service)) {
    // The server hands this factory to its threads through gRPC's own
    // atomics, which ThreadSanitizer cannot see (scripts/sanitizers/tsan.supp);
    // releasing the mutex once here orders the map's construction before its
    // first use under the lock on a gRPC thread, as TSan can see.
    absl::MutexLock publish(&mutex_);
  }

  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override {
    // Health watches are the client channels' health checking: open as long
    // as a connection lives, they end when it is recycled (as UNKNOWN), which
    // says nothing about the service and would read as errors.
    if (info->method() != nullptr &&
        absl::string_view(info->method()) == "/grpc.health.v1.Health/Watch") {
      return nullptr;
    }
    return new MetricsInterceptor(ForMethod(info->method()));
  }

 private:
  // The histogram is looked up once per method, not per call (prometheus-cpp
  // builds a histogram to look one up). Entries are keyed by the label, so
  // made-up paths share the one of "unknown".
  const MethodMetrics* ForMethod(const char* path) {
    const absl::string_view raw = path == nullptr ? "" : path;
    {
      absl::MutexLock lock(&mutex_);
      if (auto it = methods_.find(raw); it != methods_.end()) return it->second.get();
    }
    std::string method = MethodLabel(path);
    absl::MutexLock lock(&mutex_);
    std::unique_ptr<MethodMetrics>& slot = methods_[method];
    if (slot == nullptr) {
      slot = std::make_unique<MethodMetrics>();
      slot->service = service_;
      slot->method = std::move(method);
      slot->duration = &Process()->durations().Add(
          {{"service", service_}, {"method", slot->method}}, DurationBuckets());
    }
    return slot.get();
  }

  const std::string service_;
  absl::Mutex mutex_;
  absl::flat_hash_map<std::string, std::unique_ptr<MethodMetrics>> methods_ ABSL_GUARDED_BY(mutex_);
};

}  // namespace

std::unique_ptr<ScrapeGauge> ScrapeGauge::Register(const std::string& name,
                                                   const std::string& help,
                                                   Collect collect) {
  return std::unique_ptr<ScrapeGauge>(
      new ScrapeGauge(Process()->AddGauge(name, help, std::move(collect))));
}

ScrapeGauge::~ScrapeGauge() { Process()->RemoveGauge(id_); }

absl::StatusOr<std::unique_ptr<MetricsEndpoint>> MetricsEndpoint::Start(
    const std::string& address) {
  const std::size_t colon = address.rfind(':');
  int port = -1;
  if (colon == std::string::npos || !absl::SimpleAtoi(address.substr(colon + 1), &port) ||
      port < 0 || port > 65535) {
    return absl::InvalidArgumentError(
        absl::StrCat("metrics address must be host:port, got '", address, "'"));
  }
  std::string host = address.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  if (host.empty()) host = "0.0.0.0";
  std::unique_ptr<MetricsEndpoint> endpoint(new MetricsEndpoint());
  endpoint->server_ = std::make_unique<httplib::Server>();
  endpoint->server_->Get("/metrics", [](const httplib::Request&, httplib::Response& response) {
    response.set_content(prometheus::TextSerializer().Serialize(Process()->Collect()),
                         "text/plain; version=0.0.4; charset=utf-8");
  });
  absl::StatusOr<int> bound = BindHttpServer(endpoint->server_.get(), host, port, "metrics");
  if (!bound.ok()) return bound.status();
  endpoint->port_ = *bound;
  endpoint->thread_ = ServeHttpInBackground(endpoint->server_.get());
  return endpoint;
}

MetricsEndpoint::~MetricsEndpoint() {
  server_->stop();
  if (thread_.joinable()) thread_.join();
}

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> MetricsInterceptorFactory(
    const std::string& service) {
  return std::make_unique<MetricsFactory>(service);
}

}  // namespace meshseek::rpc
