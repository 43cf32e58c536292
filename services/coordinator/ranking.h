// How the services rank a rescaled collection (fused, or re-ranked: see
// common/pipeline/collection_options.h), with the same arithmetic as the
// in-process pipeline (CombineMethodDistances), so that Evaluate streams the
// same matrix bit for bit.
//
// A build leaves a RankingState (stored by the coordinator, one per
// collection): each method's distance scale, estimated over the sample rows
// of fusion.h, the models of the build in node order (the first part's
// (ordinal, id) order, which is ingest order) with their labels and
// ordinals, and, when re-ranked, the neighbour graph of the fused distances.
// Queries then need no more than each part's distances to every model:
// fused with the stored scales and re-ranked against the stored graph, the
// query joining it (rerank.h). A model ingested after the build joins the
// state for good once every part has indexed it (live ingest: a RankingJoin,
// stored beside the state and replayed on load, docs/design.md "Live
// ingest"): the next node, fused with the build's scales, entering the graph
// as a query would; a model removed since ranks nowhere.
//
// Cost of a build's ranking step: the sample rows' distances for the scales
// (O(N x kScaleRows) up to kScaleColumns models, O(kScaleColumns x
// kScaleRows) above: fusion.h), then, re-ranked, all rows (O(N^2)
// distances, in blocks of IndexShards' kMatrixBatch rows) and a partial sort
// per row; above RankingGraphOptions::exact_graph_models the approximate
// graph's O(N x candidates) distances instead (docs/design.md "Approximate
// neighbour graph"). A collection that is not re-ranked needs its models'
// ids and the scales only. Memory: the state is about 12 bytes per
// neighbour (k1 + 1 per model) plus ids and labels.
#ifndef MESHSEEK_SERVICES_COORDINATOR_RANKING_H_
#define MESHSEEK_SERVICES_COORDINATOR_RANKING_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "common/search/neighbor_graph.h"
#include "meshseek/v1/types.pb.h"
#include "services/coordinator/coordinator_options.h"
#include "services/coordinator/index_shards.h"
#include "services/coordinator/workers.h"

namespace meshseek {

struct RankingState {
  /// Each method's distance scale, in method order.
  std::vector<double> scales;
  /// The build's models in node order.
  std::vector<std::string> model_ids;
  std::vector<uint64_t> ordinals;
  std::vector<std::string> labels;
  /// The neighbour graph of the fused distances (re-ranked collections).
  std::optional<NeighborGraph> graph;

  /// "MSRS" | uint32 version (1) | uint32 methods | doubles | uint64 n |
  /// per model (uint32 length, id, uint64 ordinal, uint32 length, label) |
  /// uint8 graph present | [uint64 length, NeighborGraph bytes] | FNV-1a 64.
  std::string Serialize() const;
  /// DataLoss naming what is wrong for bytes that are not a state.
  static absl::StatusOr<RankingState> Parse(absl::string_view bytes);
};

/// A model that joined a built state (live ingest): the next node, and what
/// it changed in the graph (re-ranked collections; empty otherwise).
struct RankingJoin {
  std::string model_id;
  uint64_t ordinal = 0;
  std::string label;
  GraphJoin graph;

  /// "MSRJ" | uint32 version (1) | id, uint64 ordinal, label (as in the
  /// state) | uint32 list length, (uint32 node, float32 distance)... |
  /// uint32 entered count, (uint32, float32)... | FNV-1a 64.
  std::string Serialize() const;
  /// DataLoss naming what is wrong for bytes that are not a join.
  static absl::StatusOr<RankingJoin> Parse(absl::string_view bytes);
};

/// A parsed state ready for queries: node of each model id, fusion factors.
struct Ranking {
  std::string build;
  RankingState state;
  absl::flat_hash_map<std::string, uint32_t> node_of;
  std::vector<double> factors;  // FusionFactors(weights, scales)
  int graph_k = 0;              // the lists re-ranking asks of the graph

  static absl::StatusOr<Ranking> Make(std::string build,
                                      RankingState state,
                                      const CollectionOptions& options);

  /// The collection's distances from one row of each part's distances
  /// (node order): fused, and re-ranked when the options say so; `self` is
  /// the row's own node (Evaluate) or nullopt for a query.
  absl::StatusOr<std::vector<float>> RankRow(const std::vector<absl::Span<const float>>& part_rows,
                                             std::optional<uint32_t> self,
                                             const CollectionOptions& options) const;

  /// The join of a model not yet in the state from each part's distances to
  /// every model (as QueryDistances answered them; its own distance and
  /// those of models not in the state are ignored, models that a part did
  /// not answer are +inf). AlreadyExists when the model is a node.
  absl::StatusOr<RankingJoin> PlanJoin(
      const std::string& model_id,
      uint64_t ordinal,
      const std::string& label,
      const std::vector<std::vector<IndexShards::Scored>>& part_distances) const;
  /// Appends the join's model as the next node (and its graph changes).
  /// DataLoss for a join that does not fit this state (a stored join of
  /// another state, or damaged).
  absl::Status Apply(const RankingJoin& join);

  /// A query's top_k from each part's distances to every model (as the index
  /// answered them): models of the build answered by every part, by
  /// (distance, ordinal, id).
  absl::StatusOr<std::vector<v1::ScoredModel>> Query(
      const std::vector<std::vector<IndexShards::Scored>>& part_distances,
      const CollectionOptions& options,
      std::size_t top_k) const;
};

/// The state of `plan` after a build indexed every part: scales over the
/// sample rows, then the graph of every fused row (re-ranked collections),
/// from all pairs up to graph.exact_graph_models models and from candidates
/// above (fused_candidates.h).
absl::StatusOr<RankingState> ComputeRankingState(IndexShards* index,
                                                 const CollectionPlan& plan,
                                                 const RankingGraphOptions& graph);

/// The parts of `plan` as IndexShards parts.
std::vector<IndexShards::Part> IndexParts(const CollectionPlan& plan);

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_RANKING_H_
