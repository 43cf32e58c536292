#include "common/search/rerank.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// Weights by node, nodes increasing.
using SparseVector = std::vector<std::pair<uint32_t, double>>;

// The graph as one query sees it: the stored lists, and when the query joins
// (node n), its own list and its place in the others'.
class GraphView {
 public:
  GraphView(const NeighborGraph& graph, absl::Span<const float> row, std::optional<uint32_t> self)
      : graph_(graph), row_(row), joining_(!self.has_value()) {
    query_ = self.value_or(static_cast<uint32_t>(graph.size()));
    if (!joining_) return;
    // The query's list: itself, then its nearest models.
    std::vector<GraphNeighbor> all(graph.size());
    for (uint32_t j = 0; j < all.size(); ++j) all[j] = GraphNeighbor{j, row[j]};
    const std::size_t take = std::min<std::size_t>(all.size(), graph.k());
    const auto before = [this](const GraphNeighbor& a, const GraphNeighbor& b) {
      return NeighborBefore(query_, a, b);
    };
    std::partial_sort(all.begin(), all.begin() + take, all.end(), before);
    query_list_.push_back(GraphNeighbor{query_, 0.0f});
    query_list_.insert(query_list_.end(), all.begin(), all.begin() + take);
  }

  uint32_t query() const { return query_; }

  // The first `len` entries of x's list (fewer when the collection is smaller).
  void Neighbors(uint32_t x, int len, std::vector<GraphNeighbor>* out) const {
    out->clear();
    if (joining_ && x == query_) {
      const std::size_t m = std::min<std::size_t>(len, query_list_.size());
      out->assign(query_list_.begin(), query_list_.begin() + m);
      return;
    }
    const absl::Span<const GraphNeighbor> stored = graph_.Of(x);
    const std::size_t m = std::min<std::size_t>(len, stored.size());
    out->assign(stored.begin(), stored.begin() + m);
    if (!joining_) return;
    // The query enters x's list where it is nearer than the last kept entry
    // (its node, n, is after every other among equal distances), or anywhere
    // while the list is shorter than asked.
    const GraphNeighbor q{query_, row_[x]};
    const bool full = static_cast<int>(m) == len;
    if (full && !(q.distance < out->back().distance)) return;
    const auto at = std::upper_bound(
        out->begin() + 1, out->end(), q, [x](const GraphNeighbor& a, const GraphNeighbor& b) {
          return NeighborBefore(x, a, b);
        });
    out->insert(at, q);
    if (full) out->pop_back();
  }

 private:
  const NeighborGraph& graph_;
  absl::Span<const float> row_;
  bool joining_;
  uint32_t query_ = 0;
  std::vector<GraphNeighbor> query_list_;
};

// V(x): exp(-d) over x's k-reciprocal set, normalised.
SparseVector ReciprocalVector(const GraphView& view, uint32_t x, const RerankOptions& options) {
  const int len = options.k1 + 1;
  std::vector<GraphNeighbor> near, back;
  view.Neighbors(x, len, &near);
  SparseVector v;
  double sum = 0.0;
  for (const GraphNeighbor& y : near) {
    bool reciprocal = y.node == x;
    if (!reciprocal) {
      view.Neighbors(y.node, len, &back);
      reciprocal = std::any_of(
          back.begin(), back.end(), [x](const GraphNeighbor& e) { return e.node == x; });
    }
    if (!reciprocal) continue;
    const double w = std::exp(-static_cast<double>(y.distance));
    v.emplace_back(y.node, w);
    sum += w;
  }
  std::sort(v.begin(), v.end());
  for (auto& [node, w] : v) w /= sum;  // sum >= 1: x itself has weight exp(0)
  return v;
}

// V'(x): the mean of V over x's k2 nearest. `cache` holds V by node.
SparseVector ExpandedVector(const GraphView& view,
                            uint32_t x,
                            const RerankOptions& options,
                            absl::flat_hash_map<uint32_t, SparseVector>* cache) {
  std::vector<GraphNeighbor> near;
  view.Neighbors(x, options.k2, &near);
  std::vector<std::pair<uint32_t, double>> sum;
  for (const GraphNeighbor& z : near) {
    auto it = cache->find(z.node);
    if (it == cache->end()) {
      it = cache->emplace(z.node, ReciprocalVector(view, z.node, options)).first;
    }
    sum.insert(sum.end(), it->second.begin(), it->second.end());
  }
  // Merge equal nodes; stable so each node's terms add in list order.
  std::stable_sort(
      sum.begin(), sum.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  SparseVector out;
  for (const auto& [node, w] : sum) {
    if (!out.empty() && out.back().first == node) {
      out.back().second += w;
    } else {
      out.emplace_back(node, w);
    }
  }
  const double count = static_cast<double>(near.size());
  for (auto& [node, w] : out) w /= count;
  return out;
}

// Jaccard distance of two weight vectors: 1 - sum min / sum max.
double JaccardDistance(const SparseVector& a, const SparseVector& b) {
  double mins = 0.0, maxs = 0.0;
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && a[i].first < b[j].first)) {
      maxs += a[i++].second;
    } else if (i == a.size() || b[j].first < a[i].first) {
      maxs += b[j++].second;
    } else {
      mins += std::min(a[i].second, b[j].second);
      maxs += std::max(a[i].second, b[j].second);
      ++i;
      ++j;
    }
  }
  return maxs > 0.0 ? 1.0 - mins / maxs : 1.0;
}

absl::Status CheckInputs(const NeighborGraph& graph,
                         absl::Span<const float> row,
                         std::optional<uint32_t> self,
                         const RerankOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  const std::size_t n = graph.size();
  if (row.size() != n) {
    return absl::InvalidArgumentError(
        absl::StrCat("re-ranking: a row of ", row.size(), " distances for ", n, " models"));
  }
  if (static_cast<std::size_t>(graph.k()) < std::min<std::size_t>(options.graph_k(), n)) {
    return absl::InvalidArgumentError(absl::StrCat("re-ranking: the neighbour graph keeps ",
                                                   graph.k(),
                                                   " neighbours, k1 = ",
                                                   options.k1,
                                                   " needs ",
                                                   options.graph_k()));
  }
  if (self.has_value() && *self >= n) {
    return absl::InvalidArgumentError(
        absl::StrCat("re-ranking: model ", *self, " of ", n, " is not in the graph"));
  }
  for (std::size_t j = 0; j < n; ++j) {
    if (std::isnan(row[j]) || row[j] < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("re-ranking: distance ", row[j], " to model ", j));
    }
  }
  return absl::OkStatus();
}

// The row re-ranked against the query's V' (`query_vector`); `expanded(c)`
// gives a candidate's V'.
template <typename Expanded>
std::vector<float> Rerank(const GraphView& view,
                          absl::Span<const float> row,
                          std::optional<uint32_t> self,
                          const SparseVector& query_vector,
                          const RerankOptions& options,
                          const Expanded& expanded) {
  const std::size_t n = row.size();
  const double lambda = options.lambda;
  std::vector<float> out(n);
  for (std::size_t j = 0; j < n; ++j) {
    out[j] = std::isinf(row[j]) ? kInfinity : static_cast<float>((1.0 - lambda) + lambda * row[j]);
  }
  // The query itself (a model of the collection) and the `depth` others
  // nearest by the original distance.
  const uint32_t q = view.query();
  std::vector<GraphNeighbor> order(n);
  for (uint32_t j = 0; j < n; ++j) {
    order[j] = GraphNeighbor{j, self.has_value() && j == *self ? 0.0f : row[j]};
  }
  const std::size_t depth = std::min<std::size_t>(options.depth + (self.has_value() ? 1 : 0), n);
  std::partial_sort(
      order.begin(),
      order.begin() + depth,
      order.end(),
      [q](const GraphNeighbor& a, const GraphNeighbor& b) { return NeighborBefore(q, a, b); });
  for (std::size_t r = 0; r < depth; ++r) {
    const uint32_t c = order[r].node;
    if (std::isinf(row[c])) continue;
    const double jaccard = JaccardDistance(query_vector, expanded(c));
    out[c] = static_cast<float>((1.0 - lambda) * jaccard + lambda * order[r].distance);
  }
  if (self.has_value()) out[*self] = 0.0f;
  return out;
}

}  // namespace

absl::Status RerankOptions::Validate() const {
  const auto bad = [](const auto&... what) {
    return absl::InvalidArgumentError(absl::StrCat("re-ranking: ", what...));
  };
  if (k1 < 1 || k1 > NeighborGraph::kMaxK - 1) {
    return bad("k1 must be in [1, ", NeighborGraph::kMaxK - 1, "], got ", k1);
  }
  if (k2 < 1 || k2 > k1 + 1) return bad("k2 must be in [1, k1 + 1 = ", k1 + 1, "], got ", k2);
  if (!(lambda >= 0.0 && lambda <= 1.0)) return bad("lambda must be in [0, 1], got ", lambda);
  if (depth < 1 || depth > 100000) return bad("depth must be in [1, 100000], got ", depth);
  return absl::OkStatus();
}

absl::StatusOr<std::vector<float>> RerankRow(const NeighborGraph& graph,
                                             absl::Span<const float> row,
                                             std::optional<uint32_t> self,
                                             const RerankOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(CheckInputs(graph, row, self, options));
  if (!options.enabled()) return std::vector<float>(row.begin(), row.end());
  const GraphView view(graph, row, self);
  absl::flat_hash_map<uint32_t, SparseVector> cache;
  const SparseVector query_vector = ExpandedVector(view, view.query(), options, &cache);
  return Rerank(view, row, self, query_vector, options, [&](uint32_t c) {
    return ExpandedVector(view, c, options, &cache);
  });
}

absl::StatusOr<std::vector<float>> RerankMatrix(const NeighborGraph& graph,
                                                absl::Span<const float> distances,
                                                const RerankOptions& options,
                                                int num_threads) {
  const std::size_t n = graph.size();
  if (distances.size() != n * n) {
    return absl::InvalidArgumentError(absl::StrCat(
        "re-ranking: ", distances.size(), " distances for ", n, " models (need ", n * n, ")"));
  }
  for (std::size_t i = 0; i < n; ++i) {
    MESHSEEK_RETURN_IF_ERROR(
        CheckInputs(graph, distances.subspan(i * n, n), static_cast<uint32_t>(i), options));
  }
  if (!options.enabled()) return std::vector<float>(distances.begin(), distances.end());
  // Every model's V' once: in a model's own row the graph is the stored one,
  // so V' does not depend on the row (RerankRow computes the same values).
  std::vector<SparseVector> expanded(n);
  ParallelFor(n, num_threads, [&](std::size_t i) {
    const GraphView view(graph, distances.subspan(i * n, n), static_cast<uint32_t>(i));
    absl::flat_hash_map<uint32_t, SparseVector> cache;
    expanded[i] = ExpandedVector(view, static_cast<uint32_t>(i), options, &cache);
  });
  std::vector<float> out(n * n);
  ParallelFor(n, num_threads, [&](std::size_t i) {
    const absl::Span<const float> row = distances.subspan(i * n, n);
    const GraphView view(graph, row, static_cast<uint32_t>(i));
    const std::vector<float> ranked =
        Rerank(view, row, static_cast<uint32_t>(i), expanded[i], options, [&](uint32_t c) {
          return expanded[c];
        });
    std::copy(ranked.begin(), ranked.end(), out.begin() + i * n);
  });
  return out;
}

}  // namespace meshseek
