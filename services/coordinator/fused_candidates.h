// Each part's distances for a fused or re-ranked query (Ranking, ranking.h):
// to every model (PartDistances), or to candidates (docs/design.md "Fused
// candidates"): instead of every part's distance to every model, each
// histogram part (method) proposes its `candidates` nearest models by its
// own distance (an index Search: exact below the embedding's fit, the
// embedding's proposals re-ranked exactly above it, kl_inverted_index.h; a
// global part proposes only when no part is a histogram one, since its
// search scans every descriptor, LFD's at 18 us each: 1.8 s at 100,000),
// and every part gives its exact distance to the union of the proposals
// (Distances restricted to those model ids, from the forward index). The
// build's Ranking then fuses and re-ranks those rows as it does the whole
// ones: a model outside the union is +inf and never returned, so what can
// be lost is recall, measured against the exact fused ranking on the
// development sets (bench/fused_candidates, bench/results/fused_candidates.txt).
//
// Cost per query, P parts and C candidates: a search per histogram part
// (above the fit a 128-d scan of the embeddings and C exact distances),
// then P x |union| <= P^2 C exact distances, and the re-ranking (rerank.h, independent of N).
//
// A build of a large collection makes its neighbour graph the same way
// (ApproximateNeighborGraph below, docs/design.md "Approximate neighbour
// graph"): each model, as the query, lists its nearest among its union.
#ifndef MESHSEEK_SERVICES_COORDINATOR_FUSED_CANDIDATES_H_
#define MESHSEEK_SERVICES_COORDINATOR_FUSED_CANDIDATES_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/search/neighbor_graph.h"
#include "services/coordinator/coordinator_options.h"
#include "services/coordinator/index_shards.h"
#include "services/coordinator/workers.h"

namespace meshseek {

/// Each part's distances from its signature (one per part, in part order)
/// to every model of the part, or to the models `only` names (those of them
/// the part holds), the parts asked at once.
absl::StatusOr<std::vector<std::vector<IndexShards::Scored>>> PartDistances(
    IndexShards* index,
    const CollectionPlan& plan,
    const std::vector<const IndexSignature*>& signatures,
    const std::vector<std::string>* only = nullptr);

/// Each part's distances from its signature (one per part, in part order) to
/// the union of the parts' `candidates` nearest models, the parts asked at
/// once; in PartDistances' form, so Ranking::Query takes them as they are.
/// InvalidArgument for candidates outside [1, kMaxFusedCandidates].
absl::StatusOr<std::vector<std::vector<IndexShards::Scored>>> CandidatePartDistances(
    IndexShards* index,
    const CollectionPlan& plan,
    const std::vector<const IndexSignature*>& signatures,
    uint32_t candidates);

/// Rows of the approximate graph computed per round: each proposing part's
/// lists of this many models in one Neighbors call, then each part's missing
/// distances in one PairDistances call (about 1,024 x 150 distances).
inline constexpr std::size_t kGraphBatch = 1024;

/// The neighbour graph of the fused distances without all pairs
/// (docs/design.md "Approximate neighbour graph"): node i's list from its
/// fused distances to the union of every part's `graph_candidates` nearest
/// to it (the histogram parts propose, as CandidatePartDistances), the rest
/// of its row +inf (NeighborGraph::SetSparseRow). Computed where the
/// signatures are: kGraphBatch rows at a time, one Neighbors call per
/// proposing part, then one PairDistances call per part for what the union
/// still needs; no RPC per model. `models`: the parts' models
/// (IndexShards::ExportParts, signatures not needed), node i = row i;
/// `factors`: the fusion factors of the build's scales. O(N x candidates)
/// distances.
absl::StatusOr<NeighborGraph> ApproximateNeighborGraph(IndexShards* index,
                                                       const CollectionPlan& plan,
                                                       const IndexShards::PartModels& models,
                                                       absl::Span<const double> factors,
                                                       int k,
                                                       const RankingGraphOptions& options);

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_FUSED_CANDIDATES_H_
