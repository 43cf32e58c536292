// The candidate stage of exact KL search (kl_inverted_index.h, "Candidates"):
// the models whose embeddings (histogram_embedding.h) are nearest a query's,
// by a hierarchical navigable small-world graph (HNSW, Malkov & Yashunin
// 2018) from Faiss, over which the caller computes exact distances.
//
// Why HNSW (bench/results/candidate_search.txt, 100,000 models of 128-d
// embeddings, 2 cores): a query's 50 nearest in 0.24 ms where the scan of
// every embedding took 7.7 ms; every model's 50 nearest (a neighbour graph's
// pass) in 24 s after a 21 s build, where the scan took 772 s and Faiss'
// exact batched search 54 s; 0.997 of the exact 50 found at efSearch 64,
// 0.9996 at 128. IVF was faster to build but found 0.80 to 0.97 of them.
//
// Layout and numerics. faiss::IndexHNSWFlat (M links a node, float vectors
// in its own storage, squared L2): 512 bytes of vector and about 260 bytes
// of links a model at M = 32. Every model added gets the next Faiss id;
// `docs_` maps ids back to the caller's docs. A doc added again or removed
// leaves its old id behind as a tombstone (HNSW cannot unlink a node):
// searches skip tombstones, asking Faiss for more when they crowd the top,
// and the graph is rebuilt from the live vectors, in id order, once they
// outnumber the live models.
//
// Determinism. Faiss draws each node's level from its own seeded generator
// in add order, and adds run one vector at a time on one thread (OpenMP
// capped to the calling thread), so the same adds in the same order give the
// same graph and the same answers on every run and every restart. Searches
// call HNSW::search, Faiss' one-query, one-thread interface, directly:
// IndexHNSW::search would start an OpenMP team per call and update Faiss'
// global statistics, a data race between concurrent queries.
//
// Thread safety: Nearest may run concurrently with itself; Add, Remove and
// the move need exclusive access (KlInvertedIndex's contract).
#ifndef MESHSEEK_COMMON_SEARCH_CANDIDATE_INDEX_H_
#define MESHSEEK_COMMON_SEARCH_CANDIDATE_INDEX_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"

namespace faiss {
struct IndexHNSWFlat;
}  // namespace faiss

namespace meshseek {

struct CandidateIndexOptions {
  /// Links a node keeps per level (HNSW's M; 2 M at level 0). Memory grows
  /// with it, recall too; 32 measured (candidate_search.txt). [4, 128].
  int links = 32;
  /// Candidate list while inserting (efConstruction): Faiss' default 40,
  /// measured with it. [links, 1024].
  int build_breadth = 40;
  /// Candidate list while searching (efSearch), raised to the number of
  /// neighbours asked when that is more: 64 found 0.997 of the exact 50
  /// nearest, 128 0.9996 at 1.8 times the time. [1, 4096].
  int search_breadth = 64;

  absl::Status Check() const;
};

/// One proposal: a doc and its squared embedding distance.
struct Candidate {
  uint32_t doc = 0;
  float distance = 0.0f;
};

class CandidateIndex {
 public:
  /// An empty index of `dimensions`-d vectors; InvalidArgument for
  /// dimensions outside [1, 4096] or options that fail Check().
  static absl::StatusOr<CandidateIndex> Create(int dimensions,
                                               const CandidateIndexOptions& options = {});

  CandidateIndex(CandidateIndex&&) noexcept;
  CandidateIndex& operator=(CandidateIndex&&) noexcept;
  ~CandidateIndex();

  int dimensions() const { return dimensions_; }
  /// Live docs.
  std::size_t size() const { return id_of_.size(); }
  bool Contains(uint32_t doc) const { return id_of_.contains(doc); }

  /// Adds `doc` with `vector` (dimensions() floats), replacing its old one.
  void Add(uint32_t doc, absl::Span<const float> vector);
  /// Removes `doc`; false when it was not there.
  bool Remove(uint32_t doc);

  /// The `k` live docs whose vectors are nearest `vector`, nearest first
  /// (ties by doc), fewer only when fewer are live. Approximate: a true
  /// neighbour may be missing (see the options), never a wrong distance.
  std::vector<Candidate> Nearest(absl::Span<const float> vector, std::size_t k) const;

  /// The vector stored for `doc` (dimensions() floats), or NotFound.
  absl::StatusOr<std::vector<float>> Vector(uint32_t doc) const;

  /// Bytes of vectors, links and bookkeeping.
  std::size_t MemoryBytes() const;

 private:
  CandidateIndex(int dimensions, const CandidateIndexOptions& options);
  // Appends `vector` as the next Faiss id, for `doc`.
  void AddToGraph(uint32_t doc, const float* vector);
  // A new graph of the live vectors in id order, without tombstones.
  void Rebuild();

  int dimensions_ = 0;
  CandidateIndexOptions options_;
  std::unique_ptr<faiss::IndexHNSWFlat> graph_;
  std::vector<uint32_t> docs_;                       // Faiss id -> doc
  absl::flat_hash_map<uint32_t, int64_t> id_of_;     // live doc -> its Faiss id
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_CANDIDATE_INDEX_H_
