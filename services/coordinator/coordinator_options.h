// The coordinator's options (flags of meshseek-coordinator, fields of the
// embedded stack), with their defaults and validation.
#ifndef MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_OPTIONS_H_
#define MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_OPTIONS_H_

#include <grpcpp/security/credentials.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "common/geometry/mesh_io.h"

namespace meshseek {

/// Largest `candidates` of a fused query (fused_candidates.h): six parts'
/// unions stay within one Distances request's model ids (index.proto).
inline constexpr uint32_t kMaxFusedCandidates = 8192;

/// How a build's ranking step makes a re-ranked collection's neighbour graph
/// (docs/design.md "Approximate neighbour graph").
struct RankingGraphOptions {
  /// All pairs up to this many models, candidates above. All pairs cost
  /// O(N^2) distances; the default keeps the benchmarks' graphs (and so
  /// their matrices) exact.
  std::size_t exact_graph_models = 5000;
  /// Candidates per method of each model's list in an approximate graph, in
  /// [1, kMaxFusedCandidates]. Measured on the development sets:
  /// bench/results/fused_candidates.txt.
  uint32_t graph_candidates = 50;
  /// Candidates per method of a fused query that names none, on a
  /// collection past exact_graph_models (a whole row of a large collection
  /// is a scan of every model by every method). 100 kept recall@10 against
  /// the exact fused ranking at 0.9992 (McGill) and 0.9924 (PSB train), 50
  /// at 0.9980 and 0.9736 (bench/results/fused_candidates.txt). In [1,
  /// kMaxFusedCandidates].
  uint32_t query_candidates = 100;
  /// Models whose lists are computed at once (each mostly waits on the
  /// index), at least 1.
  int threads = 4;
};

struct CoordinatorOptions {
  /// Folder of the database (coordinator.db); created if missing.
  std::string data_dir;
  /// gRPC targets of the services (see common/rpc/client.h): "host:port",
  /// "dns:///extract:50051", "ipv4:127.0.0.1:7001,127.0.0.1:7002".
  std::string resample_target;
  std::string extract_target;
  std::string codebook_target;
  /// One target per index shard, separated by commas (index_shards.h); the
  /// number of shards is fixed once the data folder has been used.
  std::string index_target;
  /// Models being resampled/extracted at once, over all workers (the
  /// dispatcher threads). Set it to about the total worker cores.
  int max_in_flight = 8;
  /// Ingest acknowledgements wait while this many models wait for extraction.
  int max_pending = 512;
  /// Deadline of one extraction or resampling call.
  absl::Duration extract_deadline = absl::Minutes(5);
  /// Deadline of every other call to a service.
  absl::Duration call_deadline = absl::Minutes(1);
  /// Tries of a call that fails transiently (worker gone, restarting,
  /// overloaded) before the coordinator gives up on that call for now; with
  /// the backoff (0.1 s doubling to 5 s) 12 tries span about 40 s.
  int call_attempts = 12;
  /// Extraction attempts of one model. A permanent error (INVALID_ARGUMENT,
  /// DATA_LOSS, FAILED_PRECONDITION: the model itself is the problem) marks
  /// it FAILED at once; any other error is retried after `retry_backoff`,
  /// doubling up to `max_retry_backoff`, and the model is FAILED when this
  /// many attempts have failed. With the defaults a model that crashes its
  /// worker every time ends FAILED after about 4 minutes (5 attempts, each
  /// with its call retries) instead of being retried for ever.
  int model_attempts = 5;
  absl::Duration retry_backoff = absl::Seconds(2);
  absl::Duration max_retry_backoff = absl::Minutes(1);
  /// Bounds of a mesh a client sends (as a file or as arrays).
  MeshReadOptions mesh_limits;
  /// Largest message to and from the services.
  int max_message_bytes = 64 << 20;
  /// Credentials of the channels to the services (rpc::MakeChannelCredentials:
  /// TLS, a client certificate for mutual TLS); null: plaintext. And the name
  /// their certificates must carry when it is not the targets' host.
  std::shared_ptr<grpc::ChannelCredentials> service_credentials;
  std::string service_tls_name;

  /// The ranking step of builds.
  RankingGraphOptions ranking_graph;

  absl::Status Validate() const;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_OPTIONS_H_
