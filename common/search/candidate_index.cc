#include "common/search/candidate_index.h"

#include <omp.h>

#include <algorithm>
#include <limits>
#include <utility>

#include <faiss/IndexFlatCodes.h>
#include <faiss/IndexHNSW.h>
#include <faiss/impl/AuxIndexStructures.h>
#include <faiss/impl/DistanceComputer.h>
#include <faiss/impl/HNSW.h>
#include <faiss/utils/Heap.h>

#include "absl/strings/str_cat.h"

namespace meshseek {

absl::Status CandidateIndexOptions::Check() const {
  if (links < 4 || links > 128) {
    return absl::InvalidArgumentError(absl::StrCat("candidate index: links ", links,
                                                   " is not in [4, 128]"));
  }
  if (build_breadth < links || build_breadth > 1024) {
    return absl::InvalidArgumentError(absl::StrCat("candidate index: build_breadth ",
                                                   build_breadth, " is not in [links = ", links,
                                                   ", 1024]"));
  }
  if (search_breadth < 1 || search_breadth > 4096) {
    return absl::InvalidArgumentError(absl::StrCat("candidate index: search_breadth ",
                                                   search_breadth, " is not in [1, 4096]"));
  }
  return absl::OkStatus();
}

CandidateIndex::CandidateIndex(int dimensions, const CandidateIndexOptions& options)
    : dimensions_(dimensions), options_(options) {
  graph_ = std::make_unique<faiss::IndexHNSWFlat>(dimensions, options.links);
  graph_->hnsw.efConstruction = options.build_breadth;
}
CandidateIndex::CandidateIndex(CandidateIndex&&) noexcept = default;
CandidateIndex& CandidateIndex::operator=(CandidateIndex&&) noexcept = default;
CandidateIndex::~CandidateIndex() = default;

absl::StatusOr<CandidateIndex> CandidateIndex::Create(int dimensions,
                                                      const CandidateIndexOptions& options) {
  if (dimensions < 1 || dimensions > 4096) {
    return absl::InvalidArgumentError(
        absl::StrCat("candidate index: dimensions ", dimensions, " is not in [1, 4096]"));
  }
  if (absl::Status s = options.Check(); !s.ok()) return s;
  return CandidateIndex(dimensions, options);
}

void CandidateIndex::AddToGraph(uint32_t doc, const float* vector) {
  // One vector on one thread: the graph depends on the add order alone.
  omp_set_num_threads(1);
  id_of_[doc] = graph_->ntotal;
  docs_.push_back(doc);
  graph_->add(1, vector);
}

void CandidateIndex::Add(uint32_t doc, absl::Span<const float> vector) {
  Remove(doc);
  AddToGraph(doc, vector.data());
}

bool CandidateIndex::Remove(uint32_t doc) {
  if (id_of_.erase(doc) == 0) return false;
  if (docs_.size() > 2 * id_of_.size() + 64) Rebuild();
  return true;
}

void CandidateIndex::Rebuild() {
  std::vector<std::pair<int64_t, uint32_t>> live;
  live.reserve(id_of_.size());
  for (const auto& [doc, id] : id_of_) live.emplace_back(id, doc);
  std::sort(live.begin(), live.end());
  std::vector<float> vectors(live.size() * dimensions_);
  for (std::size_t i = 0; i < live.size(); ++i) {
    graph_->storage->reconstruct(live[i].first, &vectors[i * dimensions_]);
  }
  graph_ = std::make_unique<faiss::IndexHNSWFlat>(dimensions_, options_.links);
  graph_->hnsw.efConstruction = options_.build_breadth;
  docs_.clear();
  id_of_.clear();
  for (std::size_t i = 0; i < live.size(); ++i) AddToGraph(live[i].second, &vectors[i * dimensions_]);
}

std::vector<Candidate> CandidateIndex::Nearest(absl::Span<const float> vector,
                                               std::size_t k) const {
  std::vector<Candidate> out;
  const auto total = static_cast<std::size_t>(graph_->ntotal);
  if (k == 0 || id_of_.empty()) return out;
  k = std::min(k, id_of_.size());
  const std::size_t tombstones = total - id_of_.size();
  std::unique_ptr<faiss::DistanceComputer> distance(graph_->storage->get_distance_computer());
  distance->set_query(vector.data());
  faiss::VisitedTable visited(graph_->ntotal);
  // Ask for k plus room for the tombstones among them; twice as many again
  // while they crowd out live docs.
  for (std::size_t ask = std::min(total, k + std::min(tombstones, k));; ask = std::min(total, 2 * ask)) {
    std::vector<float> distances(ask);
    std::vector<faiss::Index::idx_t> ids(ask);
    faiss::maxheap_heapify(ask, distances.data(), ids.data());
    faiss::SearchParametersHNSW params;
    params.efSearch = std::max<int>(options_.search_breadth, static_cast<int>(ask));
    visited.advance();
    graph_->hnsw.search(*distance, static_cast<int>(ask), ids.data(), distances.data(), visited,
                        &params);
    const std::size_t found = faiss::maxheap_reorder(ask, distances.data(), ids.data());
    out.clear();
    for (std::size_t i = 0; i < found; ++i) {
      if (ids[i] < 0) continue;
      const uint32_t doc = docs_[static_cast<std::size_t>(ids[i])];
      const auto live = id_of_.find(doc);
      if (live != id_of_.end() && live->second == ids[i]) out.push_back({doc, distances[i]});
    }
    if (out.size() >= k || ask == total) break;
  }
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
    return a.distance < b.distance || (a.distance == b.distance && a.doc < b.doc);
  });
  if (out.size() > k) out.resize(k);
  return out;
}

absl::StatusOr<std::vector<float>> CandidateIndex::Vector(uint32_t doc) const {
  const auto it = id_of_.find(doc);
  if (it == id_of_.end()) {
    return absl::NotFoundError(absl::StrCat("candidate index: doc ", doc, " is not stored"));
  }
  std::vector<float> v(dimensions_);
  graph_->storage->reconstruct(it->second, v.data());
  return v;
}

std::size_t CandidateIndex::MemoryBytes() const {
  const auto& hnsw = graph_->hnsw;
  const auto* storage = static_cast<const faiss::IndexFlatCodes*>(graph_->storage);
  return sizeof(*this) + storage->codes.capacity() +
         hnsw.neighbors.capacity() * sizeof(hnsw.neighbors[0]) +
         hnsw.offsets.capacity() * sizeof(hnsw.offsets[0]) +
         hnsw.levels.capacity() * sizeof(hnsw.levels[0]) + docs_.capacity() * sizeof(uint32_t) +
         id_of_.capacity() * (sizeof(uint32_t) + sizeof(int64_t) + 1);
}

}  // namespace meshseek
