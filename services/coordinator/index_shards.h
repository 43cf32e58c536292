// The coordinator's view of the index: one or more index servers (shards),
// each model on exactly one of them, chosen by a stable hash of its id
// (FNV-1a 64 modulo the number of shards), so any coordinator finds it again
// without a table. Queries are scattered to every shard and their top-k
// merged; the all-pairs matrix is assembled from each shard's models and
// Distances blocks. Both are exact: distances are absolute, not relative to a
// shard.
//
// No partial answers: every shard must answer (after the usual retries of
// transient failures) or the whole call fails with that shard's status. A
// shard that holds no model of the collection answers NOT_FOUND, which counts
// as an empty part; NOT_FOUND from every shard is NOT_FOUND.
//
// The number of shards is fixed for a deployment: changing it would move
// models to other shards (the coordinator records it and refuses another).
#ifndef MESHSEEK_SERVICES_COORDINATOR_INDEX_SHARDS_H_
#define MESHSEEK_SERVICES_COORDINATOR_INDEX_SHARDS_H_

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "absl/types/span.h"
#include "common/rpc/client.h"
#include "meshseek/v1/index.grpc.pb.h"

namespace meshseek {

class IndexShards {
 public:
  /// Query histograms per Distances request while assembling a matrix.
  static constexpr int kMatrixBatch = 256;

  /// `targets`: one gRPC target per shard, separated by commas (a shard is
  /// one stateful server, so a comma never lists replicas here).
  /// InvalidArgument for an empty list or an empty target.
  static absl::StatusOr<std::vector<std::string>> ParseTargets(const std::string& targets);

  IndexShards(const std::vector<std::string>& targets,
              const rpc::ChannelOptions& channel,
              absl::Duration call_deadline,
              const rpc::RetryOptions& retry,
              const std::atomic<bool>* stop);

  std::size_t size() const { return shards_.size(); }
  /// The shard that holds `model_id`.
  std::size_t ShardOf(const std::string& model_id) const;

  /// Upsert on the model's shard.
  absl::Status Add(const v1::AddModelRequest& request);
  /// Removal on the model's shard.
  absl::StatusOr<bool> Remove(const std::string& collection, const std::string& model_id);
  /// The top_k nearest over every shard, ties by ordinal then id.
  absl::StatusOr<std::vector<v1::ScoredModel>> Search(const v1::SearchRequest& request);

  /// A query's distance to one model.
  struct Scored {
    std::string model_id;
    float distance;
  };
  /// The distances from the request's one query to every model of its
  /// collection, over every shard, in no particular order. NOT_FOUND when no
  /// shard has the collection.
  absl::StatusOr<std::vector<Scored>> QueryDistances(const v1::DistancesRequest& request);

  /// A collection whose matrix is assembled, with its distance's epsilon.
  struct Part {
    std::string collection;
    double kl_epsilon = 0;
  };
  /// Every model of some parts (one collection, or a fused collection's
  /// members) as the index holds it: `models[0]` in (ordinal, id) order gives
  /// the rows, and entry[p][i] is part p's entry of row i's model.
  struct PartModels {
    std::vector<std::vector<v1::IndexedModel>> models;  // per part, as exported
    std::vector<std::vector<const v1::IndexedModel*>> entry;
    absl::flat_hash_map<std::string, std::size_t> row_of;  // model id -> row
    std::size_t size() const { return models.empty() ? 0 : models[0].size(); }
  };
  /// NOT_FOUND when no shard has a part's collection; FAILED_PRECONDITION
  /// when the parts hold different models. Without `signatures`, the models'
  /// ids, ordinals and labels only (what a large build holds in memory).
  absl::StatusOr<PartModels> ExportParts(const std::vector<Part>& parts, bool signatures = true);

  /// Rows of a neighbour graph in batches (docs/design.md "Approximate
  /// neighbour graph"): for each of `model_ids` (models of the part), its
  /// `count` nearest models of the part over every shard, nearest first,
  /// exact distances on `candidates` proposals a shard (0: exact). A shard
  /// answers the models it holds by id; with several shards, a model is sent
  /// whole to the shards that do not hold it. At most kMaxGraphBatch ids.
  absl::StatusOr<std::vector<std::vector<Scored>>> Neighbors(const Part& part,
                                                             const std::vector<std::string>& model_ids,
                                                             uint32_t count,
                                                             uint32_t candidates);
  /// For each of `model_ids` (models of the part), its exact distances to
  /// those of `targets[i]` the part holds, in no particular order.
  absl::StatusOr<std::vector<std::vector<Scored>>> PairDistances(
      const Part& part,
      const std::vector<std::string>& model_ids,
      const std::vector<std::vector<std::string>>& targets);
  /// Most queries of one Neighbors or PairDistances call.
  static constexpr std::size_t kMaxGraphBatch = 4096;

  /// One row of the all-pairs matrices of the parts.
  struct Row {
    const v1::IndexedModel* model;  // the first part's entry
    /// Per part, the distances to every model in row order.
    std::vector<absl::Span<const float>> distances;
  };
  /// Calls fn for each model of the parts (one collection, or a fused
  /// collection's members, which hold the same models) in the first part's
  /// (ordinal, id) order with each part's distances to every model in the
  /// same order (0 to itself); with `only_rows`, for the rows at those
  /// positions (increasing) only. Returns early with fn's first error.
  /// NOT_FOUND when no shard has a part's collection; FAILED_PRECONDITION
  /// when the parts hold different models.
  absl::Status ForEachDistanceRow(const std::vector<Part>& parts,
                                  const std::function<absl::Status(const Row&)>& fn,
                                  const std::vector<std::size_t>* only_rows = nullptr);

 private:
  // The models `request` asks of shard s (empty when it has none).
  absl::StatusOr<std::vector<v1::IndexedModel>> Export(std::size_t s,
                                                       const v1::ExportModelsRequest& request);
  // The models of `model_ids` with their signatures, in that order, each
  // from its shard; Aborted for one no longer there.
  absl::StatusOr<std::vector<v1::IndexedModel>> Fetch(const Part& part,
                                                      const std::vector<std::string>& model_ids);
  // The distances from the models `ids` of `part` to every model of it, a
  // row of n per id in `column`'s order (`column`: model id -> column), from
  // every shard; Aborted when the part's models changed since `column`.
  absl::Status DistanceBlock(const Part& part,
                             const std::vector<std::string>& ids,
                             const absl::flat_hash_map<std::string, std::size_t>& column,
                             std::vector<float>* block);
  // The queries of `model_ids` as shard s takes them: by id where it holds
  // them, whole (from their shards) where it does not.
  absl::StatusOr<std::vector<std::vector<v1::QueryModel>>> QueriesPerShard(
      const Part& part, const std::vector<std::string>& model_ids);
  // Every message of a server stream of shard s, retried from the start on
  // a transient failure (`restart` drops what a failed try delivered, `take`
  // gets each message).
  template <typename Message, typename Method, typename Request, typename Restart, typename Take>
  absl::Status ReadStream(std::size_t s, Method method, const Request& request, Restart&& restart,
                          Take&& take);
  // Calls `method` on every shard at once; shard s's answer, or nullopt when
  // it does not hold the collection (NotFound). NotFound from every shard is
  // the result; any other error names its shard.
  template <typename Response, typename Request, typename Method>
  absl::StatusOr<std::vector<std::optional<Response>>> AskEveryShard(Method method,
                                                                     const Request& request);

  std::vector<std::unique_ptr<v1::Index::Stub>> shards_;
  const absl::Duration call_deadline_;
  const rpc::RetryOptions retry_;
  const std::atomic<bool>* stop_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_INDEX_SHARDS_H_
