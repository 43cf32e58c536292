#include "common/search/neighbor_graph.h"

#include <algorithm>
#include <cmath>
#include <cstring>

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
