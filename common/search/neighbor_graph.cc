#include "common/search/neighbor_graph.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "absl/container/flat_hash_set.h"
#include "absl/strings/str_cat.h"
#include "common/base/byte_order.h"
#include "common/base/hash.h"
#include "common/base/parallel.h"

namespace meshseek {
namespace {

constexpr char kMagic[4] = {'M', 'S', 'N', 'G'};
constexpr uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 4 + 4 + 8 + 4;
constexpr std::size_t kEntryBytes = 8;
constexpr std::size_t kChecksumBytes = 8;

}  // namespace

bool NeighborBefore(uint32_t self, const GraphNeighbor& a, const GraphNeighbor& b) {
  if ((a.node == self) != (b.node == self)) return a.node == self;
  // NaN never reaches here (distances are checked by the callers' inputs);
  // +inf sorts last.
  if (a.distance != b.distance) return a.distance < b.distance;
  return a.node < b.node;
}

absl::StatusOr<NeighborGraph> NeighborGraph::Create(std::size_t n, int k) {
  if (k < 1 || k > kMaxK) {
    return absl::InvalidArgumentError(
        absl::StrCat("neighbour graph: k must be in [1, ", kMaxK, "], got ", k));
  }
  if (n > kMaxNodes) {
    return absl::InvalidArgumentError(
        absl::StrCat("neighbour graph: ", n, " nodes, more than the limit of ", kMaxNodes));
  }
  NeighborGraph graph;
  graph.n_ = n;
  graph.k_ = static_cast<int>(std::min<std::size_t>(k, std::max<std::size_t>(n, 1)));
  graph.lists_.resize(n * graph.k_);
  return graph;
}

absl::StatusOr<NeighborGraph> NeighborGraph::FromMatrix(absl::Span<const float> distances,
                                                        std::size_t n,
                                                        int k,
                                                        int num_threads) {
  if (distances.size() != n * n) {
    return absl::InvalidArgumentError(absl::StrCat(
        "neighbour graph: ", distances.size(), " distances for ", n, " models (need ", n * n, ")"));
  }
  for (float d : distances) {
    if (std::isnan(d)) return absl::InvalidArgumentError("neighbour graph: a distance is NaN");
  }
  auto graph = Create(n, k);
  if (!graph.ok()) return graph.status();
  ParallelFor(n, num_threads, [&](std::size_t i) {
    graph->SetRow(static_cast<uint32_t>(i), distances.subspan(i * n, n));
  });
  return graph;
}

void NeighborGraph::SetRow(uint32_t i, absl::Span<const float> row) {
  thread_local std::vector<GraphNeighbor> all;
  all.resize(n_);
  for (std::size_t j = 0; j < n_; ++j) {
    all[j] = GraphNeighbor{static_cast<uint32_t>(j), j == i ? 0.0f : row[j]};
  }
  const auto before = [i](const GraphNeighbor& a, const GraphNeighbor& b) {
    return NeighborBefore(i, a, b);
  };
  std::partial_sort(all.begin(), all.begin() + k_, all.end(), before);
  std::copy(all.begin(), all.begin() + k_, lists_.begin() + static_cast<std::size_t>(i) * k_);
}

void NeighborGraph::SetSparseRow(uint32_t i, absl::Span<const GraphNeighbor> known) {
  thread_local std::vector<GraphNeighbor> finite;
  thread_local absl::flat_hash_set<uint32_t> listed;
  finite.assign(1, GraphNeighbor{i, 0.0f});
  for (const GraphNeighbor& nb : known) {
    if (nb.node != i && std::isfinite(nb.distance)) finite.push_back(nb);
  }
  const auto before = [i](const GraphNeighbor& a, const GraphNeighbor& b) {
    return NeighborBefore(i, a, b);
  };
  const std::size_t k = static_cast<std::size_t>(k_);
  const std::size_t take = std::min(k, finite.size());
  std::partial_sort(finite.begin(), finite.begin() + take, finite.end(), before);
  GraphNeighbor* list = lists_.data() + static_cast<std::size_t>(i) * k;
  std::copy(finite.begin(), finite.begin() + take, list);
  // The rest at +inf, by node, as SetRow orders them.
  listed.clear();
  for (const GraphNeighbor& nb : finite) listed.insert(nb.node);
  std::size_t at = take;
  for (uint32_t j = 0; at < k && j < n_; ++j) {
    if (!listed.contains(j)) list[at++] = GraphNeighbor{j, std::numeric_limits<float>::infinity()};
  }
}

GraphJoin NeighborGraph::PlanJoin(absl::Span<const float> row, int k) const {
  const uint32_t self = static_cast<uint32_t>(n_);
  // Lists keep their length k_, or grow by one while they hold every node.
  const bool grow = k_ > 0 && static_cast<std::size_t>(k_) == n_ && k > k_;
  const std::size_t take = k_ > 0 ? static_cast<std::size_t>(grow ? k_ : k_ - 1) : 0;
  GraphJoin join;
  std::vector<GraphNeighbor> all(n_);
  for (uint32_t j = 0; j < n_; ++j) all[j] = GraphNeighbor{j, row[j]};
  std::partial_sort(all.begin(), all.begin() + take, all.end(),
                    [self](const GraphNeighbor& a, const GraphNeighbor& b) {
                      return NeighborBefore(self, a, b);
                    });
  join.list.push_back(GraphNeighbor{self, 0.0f});
  join.list.insert(join.list.end(), all.begin(), all.begin() + take);
  for (uint32_t y = 0; y < n_; ++y) {
    if (grow || row[y] < Of(y).back().distance) join.entered.push_back(GraphNeighbor{y, row[y]});
  }
  return join;
}

absl::Status NeighborGraph::ApplyJoin(const GraphJoin& join) {
  const uint32_t self = static_cast<uint32_t>(n_);
  if (k_ < 1) return absl::InvalidArgumentError("neighbour graph: joined before Create");
  if (n_ + 1 > kMaxNodes) return absl::InvalidArgumentError("neighbour graph: full");
  const bool grow = static_cast<std::size_t>(k_) == n_ && join.list.size() == n_ + 1 &&
                    k_ < kMaxK;
  const std::size_t length = static_cast<std::size_t>(k_) + (grow ? 1 : 0);
  if (join.list.size() != length || join.list.front().node != self) {
    return absl::InvalidArgumentError(absl::StrCat(
        "neighbour graph: a join list of ", join.list.size(), " for lists of ", k_));
  }
  for (std::size_t j = 1; j < join.list.size(); ++j) {
    const GraphNeighbor& e = join.list[j];
    if (e.node >= n_ || std::isnan(e.distance) || e.distance < 0 ||
        !NeighborBefore(self, join.list[j - 1], e)) {
      return absl::InvalidArgumentError(
          absl::StrCat("neighbour graph: join list entry ", j, " is not a node in order"));
    }
  }
  for (const GraphNeighbor& e : join.entered) {
    if (e.node >= n_ || std::isnan(e.distance) || e.distance < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("neighbour graph: join enters list ", e.node, " of ", n_));
    }
  }
  if (grow && join.entered.size() != n_) {
    return absl::InvalidArgumentError("neighbour graph: a growing join must enter every list");
  }
  if (grow) {
    // Every list one longer: re-laid out with a free last slot.
    std::vector<GraphNeighbor> wider(n_ * length);
    for (std::size_t i = 0; i < n_; ++i) {
      std::copy(lists_.begin() + i * k_, lists_.begin() + (i + 1) * k_, wider.begin() + i * length);
      wider[i * length + k_] = GraphNeighbor{self, std::numeric_limits<float>::infinity()};
    }
    lists_.swap(wider);
    k_ = static_cast<int>(length);
  }
  for (const GraphNeighbor& e : join.entered) {
    GraphNeighbor* list = lists_.data() + static_cast<std::size_t>(e.node) * k_;
    const GraphNeighbor entry{self, e.distance};
    // A grown list's free slot is the new node's own: search before it.
    GraphNeighbor* end = list + k_ - (grow ? 1 : 0);
    GraphNeighbor* at = std::upper_bound(
        list + 1, end, entry, [&e](const GraphNeighbor& a, const GraphNeighbor& b) {
          return NeighborBefore(e.node, a, b);
        });
    if (!grow && at == end) continue;  // not nearer than the last after all
    std::copy_backward(at, list + k_ - 1, list + k_);
    *at = entry;
  }
  lists_.insert(lists_.end(), join.list.begin(), join.list.end());
  ++n_;
  return absl::OkStatus();
}

std::string NeighborGraph::Serialize() const {
  std::string out(kMagic, sizeof(kMagic));
  out.reserve(kHeaderBytes + lists_.size() * kEntryBytes + kChecksumBytes);
  PutLittleEndian(kVersion, 4, &out);
  PutLittleEndian(n_, 8, &out);
  PutLittleEndian(static_cast<uint32_t>(k_), 4, &out);
  for (const GraphNeighbor& e : lists_) {
    PutLittleEndian(e.node, 4, &out);
    PutFloat(e.distance, &out);
  }
  PutLittleEndian(Fnv1a64(out), 8, &out);
  return out;
}

absl::StatusOr<NeighborGraph> NeighborGraph::Parse(absl::string_view bytes) {
  const auto bad = [](const auto&... what) {
    return absl::DataLossError(absl::StrCat("neighbour graph: ", what...));
  };
  if (bytes.size() < kHeaderBytes + kChecksumBytes) {
    return bad(bytes.size(), " bytes, shorter than the header and checksum");
  }
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) return bad("bad magic");
  const uint64_t version = GetLittleEndian(bytes.data() + 4, 4);
  if (version != kVersion) return bad("unsupported version ", version);
  const uint64_t n = GetLittleEndian(bytes.data() + 8, 8);
  const uint64_t k = GetLittleEndian(bytes.data() + 16, 4);
  if (k < 1 || k > kMaxK || n > kMaxNodes || k > std::max<uint64_t>(n, 1)) {
    return bad("header says ", n, " nodes with lists of ", k);
  }
  // n <= 2^31 and k <= 1024 bound the product before it is compared.
  if (bytes.size() != kHeaderBytes + n * k * kEntryBytes + kChecksumBytes) {
    return bad(bytes.size(), " bytes for ", n, " lists of ", k);
  }
  const std::size_t body = bytes.size() - kChecksumBytes;
  if (Fnv1a64(bytes.substr(0, body)) != GetLittleEndian(bytes.data() + body, 8)) {
    return bad("checksum mismatch");
  }
  auto graph = Create(n, static_cast<int>(k));
  if (!graph.ok()) return bad(graph.status().message());
  if (graph->k_ != static_cast<int>(k)) return bad("lists of ", k, " for ", n, " nodes");
  const char* p = bytes.data() + kHeaderBytes;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < k; ++j, p += kEntryBytes) {
      GraphNeighbor e{static_cast<uint32_t>(GetLittleEndian(p, 4)), GetFloat(p + 4)};
      if (e.node >= n || std::isnan(e.distance) || e.distance < 0) {
        return bad("list ", i, " entry ", j, ": node ", e.node, " distance ", e.distance);
      }
      if ((j == 0) != (e.node == i) ||
          (j > 0 && !NeighborBefore(static_cast<uint32_t>(i), graph->lists_[i * k + j - 1], e))) {
        return bad("list ", i, " is not in order at entry ", j);
      }
      graph->lists_[i * k + j] = e;
    }
  }
  return graph;
}

}  // namespace meshseek
