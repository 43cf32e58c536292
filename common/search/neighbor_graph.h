// The k-nearest-neighbour graph of a collection: for every model its k
// nearest models by the collection's distance, itself first. Re-ranking
// (rerank.h) works on this graph rather than on the N x N matrix, so that a
// query's re-ranking costs the same at 1,000 models as at 1,000,000 once the
// graph is built.
//
// Nodes are the models in collection order, 0 .. n - 1. List i holds
// min(k, n) neighbours: node i itself at distance 0, then the others by
// increasing distance, ties by node; +inf distances (models without
// features) rank last like any other.
//
// Serialised form (for the coordinator to store a built graph),
// little-endian: "MSNG" | uint32 version (1) | uint64 n | uint32 k |
// n * min(k, n) (uint32 node, float32 distance) | uint64 FNV-1a 64 of every
// preceding byte. Parse checks every count against the bytes present, every
// node against n, the order of each list, and the hash.
#ifndef MESHSEEK_COMMON_SEARCH_NEIGHBOR_GRAPH_H_
#define MESHSEEK_COMMON_SEARCH_NEIGHBOR_GRAPH_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"

namespace meshseek {

struct GraphNeighbor {
  uint32_t node = 0;
  float distance = 0.0f;
  bool operator==(const GraphNeighbor& o) const { return node == o.node && distance == o.distance; }
};

/// What a new node changes in a graph (NeighborGraph::PlanJoin): its own
/// list, and the lists it enters, each as (node whose list it enters, the
/// distance between them). Small: k entries, and on average about k entered
/// lists, so a live collection can store it per model and replay it.
struct GraphJoin {
  std::vector<GraphNeighbor> list;
  std::vector<GraphNeighbor> entered;
};

/// Orders neighbours of `self`'s list: itself first, then by (distance, node).
bool NeighborBefore(uint32_t self, const GraphNeighbor& a, const GraphNeighbor& b);

class NeighborGraph {
 public:
  /// Largest supported list length.
  static constexpr int kMaxK = 1024;
  /// Largest supported collection.
  static constexpr std::size_t kMaxNodes = std::size_t{1} << 31;

  NeighborGraph() = default;

  /// Starts an empty graph of `n` nodes with lists of `k`; fill it with
  /// SetRow. InvalidArgument for k outside [1, kMaxK] or n past kMaxNodes.
  static absl::StatusOr<NeighborGraph> Create(std::size_t n, int k);

  /// The graph of a dense n x n row-major distance matrix (row i: distances
  /// from model i), rows on up to `num_threads` threads (<= 0: all cores).
  static absl::StatusOr<NeighborGraph> FromMatrix(absl::Span<const float> distances,
                                                  std::size_t n,
                                                  int k,
                                                  int num_threads = 0);

  /// Sets node i's list from its row of distances to every node (n values;
  /// the entry for i itself is ignored). Rows may be set from several
  /// threads at once, each row by one.
  void SetRow(uint32_t i, absl::Span<const float> row);

  /// Sets node i's list from its distances to some nodes only (`known`,
  /// each node at most once, < n; an entry for i itself is ignored), every
  /// other node at +inf: the list SetRow sets from that row, in
  /// O(|known| log |known| + k) rather than O(n). What an approximate graph
  /// is built from (docs/design.md "Approximate neighbour graph").
  void SetSparseRow(uint32_t i, absl::Span<const GraphNeighbor> known);

  /// Live growth (docs/design.md, "Live ingest"). The join of a new node
  /// n = size() from its distances to nodes 0 .. n - 1 (`row`, n values, none
  /// NaN), in a graph whose lists were asked to hold `k` (as at Create): its
  /// list as SetRow would set it, and every list whose last entry it is
  /// nearer than (strictly: the older node keeps a tie, as NeighborBefore
  /// orders them). A graph that holds every node in every list (fewer nodes
  /// than k) grows its lists by one instead, the new node entering each.
  /// Applied, the graph is the one FromMatrix(.., n + 1, k) would build.
  GraphJoin PlanJoin(absl::Span<const float> row, int k) const;
  /// Appends node size() as `join` says. InvalidArgument (and nothing
  /// changed) for a join of another graph: a list of another length, out of
  /// order, or naming a node that does not exist.
  absl::Status ApplyJoin(const GraphJoin& join);

  std::size_t size() const { return n_; }
  /// List length: min(k, n) (k for an empty graph).
  int k() const { return k_; }
  absl::Span<const GraphNeighbor> Of(uint32_t node) const {
    return absl::MakeConstSpan(lists_.data() + static_cast<std::size_t>(node) * k_, k_);
  }

  std::string Serialize() const;
  /// DataLoss naming what is wrong for bytes that are not a graph.
  static absl::StatusOr<NeighborGraph> Parse(absl::string_view bytes);

  bool operator==(const NeighborGraph& o) const {
    return n_ == o.n_ && k_ == o.k_ && lists_ == o.lists_;
  }

 private:
  std::size_t n_ = 0;
  int k_ = 0;
  std::vector<GraphNeighbor> lists_;  // n x k
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_NEIGHBOR_GRAPH_H_
