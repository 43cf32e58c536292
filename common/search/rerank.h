// Unsupervised re-ranking over the collection's own neighbour graph:
// k-reciprocal encoding (Zhong, Zheng, Cao & Li, "Re-ranking person
// re-identification with k-reciprocal encoding", CVPR 2017), which uses
// nothing but the distances, so it fits the paper's protocol (no labels).
//
// Two models that are each other's near neighbours are likely of one class;
// two models whose reciprocal neighbourhoods overlap are likely too, even when
// their own distance is not small (an articulated pose far from the query but
// near the query's neighbours). For a model x with k nearest N(x, k) (x
// itself first, from the NeighborGraph):
//   R(x)  = { y in N(x, k1 + 1) : x in N(y, k1 + 1) }, its k-reciprocal set;
//   V(x)  = exp(-d(x, y)) on y in R(x), 0 elsewhere, normalised to sum 1;
//   V'(x) = the mean of V(z) over z in N(x, k2) (local query expansion);
//   d_J(q, c) = 1 - sum min(V'(q), V'(c)) / sum max(V'(q), V'(c));
//   d*(q, c)  = (1 - lambda) d_J(q, c) + lambda d(q, c).
// Zhong et al.'s second expansion of R (adding the half-size sets of its
// members) needs distances between models two hops apart, which the graph
// does not keep; it is left out. Manifold ranking (diffusion over the whole
// graph, bench/fusion_sweep --manifold) was measured beside it on the
// default fusion: first tier equal on McGill, 0.7 lower on PSB train, better
// second tier and DCG, but a query joining the graph then costs iterations
// over every edge of the collection (bench/results/fusion.txt);
// k-reciprocal's cost stays bounded.
//
// Cost. A query's re-ranking reads only the graph lists of its `depth`
// nearest candidates, their k2 nearest and those lists' members: about
// depth * k2 * (k1 + 1)^2 list entries, independent of the collection size
// (bench/results/rerank.txt: one query joining 100,000 models, every row of
// PSB train).
// Candidates beyond `depth` share no reciprocal neighbour worth finding and
// keep d_J = 1, so every model keeps a distance and one order:
// d* = (1 - lambda) + lambda d for them, above every re-ranked candidate's
// d* when its d_J < 1. Models at distance +inf stay at +inf.
//
// A query from outside the collection joins the graph: it enters the list of
// every model y it is nearer to than y's (k1 + 1)-th neighbour (exactly what
// the list would be had the query been a model when the graph was built), and
// its own list is its nearest models. A model of the collection queried with
// its own row (eval) gives the same as its row of RerankMatrix, bit for bit.
//
// Distances must be on a scale where exp(-d) discriminates: the pipeline
// divides each method's distances by their mean over the collection
// (fusion.h), so d is about 1 on average and near neighbours are well below.
#ifndef MESHSEEK_COMMON_SEARCH_RERANK_H_
#define MESHSEEK_COMMON_SEARCH_RERANK_H_

#include <cstdint>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/search/neighbor_graph.h"

namespace meshseek {

struct RerankOptions {
  // Defaults measured on the development sets with the fused
  // bfdsift+rld+lsf+lfd (bench/results/fusion.txt): of k1 in {10, 15, 20,
  // 30}, k2 in {1, 2, 4, 6}, lambda in {0, 0.1, 0.2, 0.3}, (20, 4, 0.1) has
  // the best mean first tier over McGill and PSB train.
  enum class Method {
    /// The distances as they are.
    kNone,
    /// k-reciprocal encoding, above.
    kKReciprocal,
  };
  Method method = Method::kKReciprocal;
  /// Neighbourhood whose reciprocal members describe a model.
  int k1 = 20;
  /// Local query expansion: V' averages V over this many nearest (1: none).
  int k2 = 4;
  /// Weight of the original distance in the result.
  double lambda = 0.1;
  /// Models re-ranked per query: the nearest by the original distance, not
  /// counting the query itself. 200 measured +0.6 / +0.2 over 100 on McGill
  /// and PSB train, 1,000 another +0.5 / +0.1 (bench/results/fusion.txt).
  int depth = 200;

  bool enabled() const { return method != Method::kNone; }
  /// List length the neighbour graph must have: k1 + 1.
  int graph_k() const { return k1 + 1; }
  /// InvalidArgument naming the first bad field and its value.
  absl::Status Validate() const;
};

/// The re-ranked distances from one query to every model of `graph`.
/// `row`: the query's distance to every model (graph.size() values, >= 0 or
/// +inf). `self`: the query's own node when it is a model of the collection,
/// nullopt when it joins the graph. InvalidArgument for a row of another size,
/// a NaN or negative distance, a graph with lists shorter than
/// min(graph_k(), n), or a self outside the graph.
absl::StatusOr<std::vector<float>> RerankRow(const NeighborGraph& graph,
                                             absl::Span<const float> row,
                                             std::optional<uint32_t> self,
                                             const RerankOptions& options);

/// Every row of the n x n matrix re-ranked as RerankRow(graph, row i, i),
/// rows on up to `num_threads` threads (<= 0: all cores); the same bits.
absl::StatusOr<std::vector<float>> RerankMatrix(const NeighborGraph& graph,
                                                absl::Span<const float> distances,
                                                const RerankOptions& options,
                                                int num_threads = 0);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_RERANK_H_
