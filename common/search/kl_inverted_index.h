// Exact symmetric-KL search over sparse histograms with an inverted file: the
// index engine of the index service and the ranking of `eval`.
//
// The distance is the one of kl_divergence.h (docs/design.md 2.7): add epsilon to
// every bin of a histogram x summing to 1, renormalise, x'_k = c (x_k + eps)
// with c = 1 / (1 + V eps), and
//
//   D(x, y) = sum_k (x'_k - y'_k)(ln x'_k - ln y'_k).
//
// Derivation (docs/design.md 2.7a). ln x'_k - ln y'_k = ln((x_k + eps) / (y_k + eps))
// = g(x_k) - g(y_k) with g(t) = ln(1 + t / eps), so g(0) = 0, and
// x'_k - y'_k = c (x_k - y_k). Hence
//
//   D(x, y) = c sum_k (x_k - y_k)(g(x_k) - g(y_k))
//           = c sum_k [x_k g(x_k) + y_k g(y_k) - x_k g(y_k) - y_k g(x_k)].
//
// A word used by neither model contributes 0 (x = y = 0, g(0) = 0); a word used
// by x only contributes x_k g(x_k), and one used by y only y_k g(y_k). So with
// the per-model constant A(x) = sum_{k in supp x} x_k g(x_k),
//
//   D(x, y) = c [A(x) + A(y) - sum_{k in supp x and supp y} (x_k g(y_k) + y_k g(x_k))].
//
// An inverted file (word -> postings of (model, weight, g(weight))) therefore
// gives a query's distance to every model by touching only the postings of the
// query's words, plus one pass over the constants; the all-pairs matrix is a
// sparse product. V eps is about 2e-7 at the defaults, so c is 1 to 7 digits.
//
// Exact for any input sum. Histograms arrive as float weights summing to 1
// only within a tolerance, and the pairwise code normalises each by its own
// sum: x' = c_x (x + eps), c_x = 1 / (s_x + V eps), s_x = sum_k x_k. The
// derivation above still holds term by term with a constant per model: since
// sum_k x'_k = sum_k y'_k = 1, the ln c_x - ln c_y part of ln x' - ln y'
// cancels, and regrouping the expansion gives
//
//   D(x, y) = c_x (a_x - a_xy) + c_y (a_y - a_yx) + (e_x - e_y)(G_x - G_y)
//
// with e_x = eps c_x, a_x = sum_k x_k g(x_k), G_x = sum_k g(x_k) (over supp x),
// and the two common sums a_xy = sum x_k g(y_k), a_yx = sum y_k g(x_k) over
// supp x and supp y. The index stores each weight as given (so a histogram read
// back is the one stored) and never renormalises.
//
// Numerics. g is kept as float beside the float weight, and a query's g is
// rounded to float the same way, so every product x_k g(y_k) is the same
// double from either side. Sums run in double in increasing word order.
// Consequences, pinned by tests: D(x, x) = 0 exactly (a_xy is then a_x term
// for term); D(x, y) and D(y, x) are the same float (the formula above only
// swaps the operands of commutative operations), so the all-pairs matrix is
// exactly symmetric and equals one query at a time bit for bit. Negative
// results of cancellation are clamped to 0. Against the pairwise dense code
// (kl_divergence.h) the only difference is the float rounding of g, about
// 6e-8 of a_x ~ 20: distances agree to a relative 1e-5, and rankings agree
// except between distances that close.
//
// Layout. Models live in segments of up to 16,384 slots. A segment keeps a
// dictionary of the distinct weights of its models (with their g), and per
// word the postings of its models as two arrays of 16-bit numbers, slot and
// value id, slots increasing: 4 bytes a posting. Bag-of-features weights are
// counts over a model's feature count, so a segment sees few distinct values;
// a model whose new values would overflow the 65,536 ids opens a new segment.
// Per slot it keeps the constants and a live flag. A query runs segment by
// segment (in parallel), accumulating the two common sums of the segment's
// models in a 256 KB array that stays in L2, with the dictionary beside it.
// It streams only the postings of the query's words: exact search is bound by
// memory bandwidth. Adds go to the last segment; removal clears the live flag,
// and a segment whose dead slots exceed half is rewritten without them. At
// 100,000 models of 920 words the postings take 370 MB (and the forward
// index of the candidate stage as much again).
//
// Candidates. Exact search streams 4 bytes for most of a dense collection's
// postings per query (at V = 2,000 about half the words are used): 170 MB at
// 100,000 models, over 12 ms at the 12 GB/s of the development machine, 35 ms
// measured. For large collections Search can instead re-rank candidates: each
// model also has a 128-d embedding (histogram_embedding.h), the square root of
// its histogram projected on the principal axes of the square roots of the
// collection, whose distances approximate the Hellinger distance, a close
// proxy of symmetric KL's ranking. The axes are fitted once, when the index
// first holds kEmbeddingFitModels models, on those models (an index restarted
// from the same adds fits the same axes); models added later are embedded on
// them. The models with the nearest embeddings, found by an HNSW graph
// (candidate_index.h: 0.24 ms a query at 100,000 models where a scan of
// every embedding took 7.7), are re-ranked with exact
// distances computed from a forward index (per model its words and value ids,
// 4 bytes each), in word order with the query held as dense arrays: the same
// doubles as the exact scan, so a candidate's distance is bit for bit its
// exact distance; only recall can be lost, and it is measured on real
// histograms (bench/rank_check, bench/index_benchmark, README). Memory:
// forward index as large as the postings, about 800 bytes of embedding and
// graph links per model.
//
// Storage (issue 37: memory that does not grow with the vocabulary). The
// forward index lives in a ForwardStore (forward_store.h): in memory, or in
// an unlinked file read with pread (KlIndexStorage::forward_dir), 4 bytes an
// entry either way; the process then keeps 12 bytes of offsets a model.
// Postings are kept while the index holds at most
// KlIndexStorage::postings_max_models models; past that they are freed and
// a full scan reads every live model's forward entries against the query as
// dense arrays: the same doubles (each model's words in word order, zero
// terms elsewhere), so every distance stays bit for bit the one the postings
// give, at O(all entries) instead of O(the query's postings). That is the
// trade a service makes for a collection too large to scan often: its
// queries go through candidates, and its builds ask full rows only for the
// scale's sample (docs/design.md 4.4).
//
// Models without words (no local features) have no distance to anything: +inf
// to every other model, and as a query every distance is +inf (0 only from a
// model to itself in the all-pairs matrix), the rule of the pipeline.
//
// Not thread-safe for writes: const methods may run concurrently with each
// other, writers need exclusive access (the index service holds a
// reader/writer lock).
#ifndef MESHSEEK_COMMON_SEARCH_KL_INVERTED_INDEX_H_
#define MESHSEEK_COMMON_SEARCH_KL_INVERTED_INDEX_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/bof/kl_divergence.h"
#include "common/search/candidate_index.h"
#include "common/search/histogram_embedding.h"
#include "common/search/sparse_histogram.h"

namespace meshseek {

class ForwardStore;

/// Where a KlInvertedIndex keeps what grows with its models (see "Storage").
struct KlIndexStorage {
  /// Folder of the forward index's file (an unlinked temporary: nothing to
  /// clean up or check after a crash); empty: in memory.
  std::string forward_dir;
  /// Postings are freed once the index holds more models than this; the
  /// default keeps them always. The index service sets 20,000
  /// (index_service.h). At least 1.
  std::size_t postings_max_models = std::numeric_limits<std::size_t>::max();

  absl::Status Check() const;
};

/// One model's distance to a query. `doc` is the caller's id of the model.
struct KlNeighbor {
  uint32_t doc = 0;
  float distance = 0.0f;
};

class KlInvertedIndex {
 public:
  /// Largest number of models in one segment (16-bit slots).
  static constexpr std::size_t kSegmentSlots = 1 << 14;
  /// Dimensions of the embedding that proposes candidates.
  static constexpr std::size_t kEmbeddingDimensions = 128;
  /// The embedding is fitted when the index first holds this many models, on
  /// them; below, Search with candidates scans exactly (it is fast there).
  static constexpr std::size_t kEmbeddingFitModels = 2048;

  /// An empty index for histograms over `vocabulary` words; InvalidArgument
  /// for vocabulary 0 or invalid options, Internal when the forward file
  /// cannot be made.
  static absl::StatusOr<KlInvertedIndex> Create(uint32_t vocabulary,
                                                const KlDivergenceOptions& options = {},
                                                const KlIndexStorage& storage = {});

  KlInvertedIndex(KlInvertedIndex&&) noexcept;
  KlInvertedIndex& operator=(KlInvertedIndex&&) noexcept;
  ~KlInvertedIndex();

  uint32_t vocabulary() const { return vocabulary_; }
  const KlDivergenceOptions& options() const { return options_; }
  const KlIndexStorage& storage() const { return storage_; }
  /// Whether postings are kept (see "Storage").
  bool has_postings() const { return postings_; }
  /// Number of models.
  std::size_t size() const { return locations_.size(); }
  bool Contains(uint32_t doc) const { return locations_.contains(doc); }

  /// Adds model `doc` with `histogram`, replacing what `doc` held before.
  /// InvalidArgument (naming `doc`) for a histogram that fails Validate() or
  /// has another vocabulary, Internal when the forward file cannot grow; the
  /// index is then unchanged.
  absl::Status Upsert(uint32_t doc, const SparseHistogram& histogram);
  /// Removes `doc`; false when it was not there.
  bool Remove(uint32_t doc);

  /// Calls fn(doc, histogram) for every model, the histogram exactly as it
  /// was given, from the forward index.
  void ForEach(const std::function<void(uint32_t, const SparseHistogram&)>& fn) const;

  /// The histogram stored for `doc`, exactly as it was given, or NotFound;
  /// from the forward index, O(its words).
  absl::StatusOr<SparseHistogram> Histogram(uint32_t doc) const;

  /// Distances from `query` to every model, in no particular order.
  /// InvalidArgument for an invalid query. Segments run on up to
  /// `num_threads` threads (<= 0: all cores); the values never depend on it.
  absl::StatusOr<std::vector<KlNeighbor>> Distances(const SparseHistogram& query,
                                                    int num_threads) const;

  /// Distances from `query` to each of `docs`, in that order, bit for bit the
  /// values Distances gives them, from the forward index: O(words of those
  /// models), not a scan of the postings (what a fused query's candidates
  /// need, docs/design.md "Fused candidates"). NotFound for a doc that is not
  /// stored; InvalidArgument for an invalid query.
  absl::StatusOr<std::vector<KlNeighbor>> DistancesTo(const SparseHistogram& query,
                                                      absl::Span<const uint32_t> docs,
                                                      int num_threads) const;

  /// The `k` nearest models to `query` by (distance, doc), followed by any
  /// others at the k-th distance (so a caller may break ties its own way).
  /// `candidates` = 0: exact, every model scanned. Otherwise the k nearest
  /// among the `candidates` (>= k) models whose embeddings are nearest the
  /// query's, with exact distances (see "Candidates" above); the exact scan
  /// when there are no more models than that.
  absl::StatusOr<std::vector<KlNeighbor>> Search(const SparseHistogram& query,
                                                 std::size_t k,
                                                 int num_threads,
                                                 std::size_t candidates = 0) const;
  /// Search for stored model `doc`'s histogram (itself among the answers, at
  /// 0), bit for bit, without preparing or embedding it again: a neighbour
  /// graph's rows. NotFound when `doc` is not stored.
  absl::StatusOr<std::vector<KlNeighbor>> SearchStored(uint32_t doc,
                                                       std::size_t k,
                                                       int num_threads,
                                                       std::size_t candidates = 0) const;
  /// DistancesTo for stored model `doc`'s histogram, bit for bit.
  absl::StatusOr<std::vector<KlNeighbor>> DistancesFromStored(uint32_t doc,
                                                              absl::Span<const uint32_t> docs,
                                                              int num_threads) const;

  /// All pairs among `docs` (each stored): docs.size()^2 row-major, entry
  /// i * n + j = D(docs[i], docs[j]); exactly symmetric, zero diagonal.
  /// NotFound for a doc that is not stored.
  absl::StatusOr<std::vector<float>> DistanceMatrix(const std::vector<uint32_t>& docs,
                                                    int num_threads) const;

  /// Fits the candidate embedding on every stored model now and embeds them
  /// all (refitting if there was one). Done automatically when the index
  /// reaches kEmbeddingFitModels; benchmarks call it to measure the candidate
  /// stage on smaller real collections.
  void FitEmbedding();
  bool has_embedding() const { return embedding_.has_value(); }

  /// Bytes held by postings, constants and bookkeeping (capacity, not size).
  std::size_t MemoryBytes() const;
  /// Bytes of the forward index's file (0 in memory).
  uint64_t FileBytes() const;

 private:
  struct Segment;
  struct Location {
    uint32_t segment;
    uint16_t slot;
  };
  // A histogram prepared once: words, weights, float-rounded g and the
  // constants c, e, a, G of the formula above.
  struct PreparedQuery;
  // A prepared query as dense arrays (forward sums).
  struct DenseQuery;

  KlInvertedIndex(uint32_t vocabulary,
                  const KlDivergenceOptions& options,
                  const KlIndexStorage& storage,
                  std::unique_ptr<ForwardStore> forward);
  absl::StatusOr<PreparedQuery> Prepare(const SparseHistogram& histogram,
                                        absl::string_view name) const;
  // Stored model `doc` as a prepared query, with its embedding if asked.
  absl::StatusOr<PreparedQuery> StoredQuery(uint32_t doc, bool embedded) const;
  std::vector<KlNeighbor> Search(const PreparedQuery& query,
                                 std::size_t k,
                                 int num_threads,
                                 std::size_t candidates) const;
  absl::StatusOr<std::vector<KlNeighbor>> DistancesTo(const PreparedQuery& query,
                                                      absl::Span<const uint32_t> docs,
                                                      int num_threads) const;
  std::vector<KlNeighbor> AllDistances(const PreparedQuery& query, int num_threads) const;
  // Exact distances to the `candidates` models the embedding puts nearest.
  std::vector<KlNeighbor> RerankCandidates(const PreparedQuery& query,
                                           std::size_t candidates,
                                           int num_threads) const;
  // Exact distances to the models at `at`, from the forward index.
  std::vector<KlNeighbor> ForwardDistances(const PreparedQuery& query,
                                           const std::vector<Location>& at,
                                           int num_threads) const;
  // D from the common sums (the formula above).
  static double Combine(const PreparedQuery& query,
                        const Segment& segment,
                        std::size_t slot,
                        double query_side,
                        double model_side);
  // Appends a prepared histogram to the last segment (a new one when full),
  // fitting the embedding when the index reaches kEmbeddingFitModels and
  // freeing the postings past postings_max_models; unchanged on an error.
  absl::Status Append(uint32_t doc, const PreparedQuery& prepared);
  // Marks a slot dead, compacting its segment or the forward store when
  // dead entries outnumber live ones.
  void RemoveSlot(Location at);
  // The live slots' forward entries into a new store (kept on an error).
  void RewriteForward();
  // q's embedding (embedding_ is fitted).
  void Embed(PreparedQuery* q) const;
  // Calls emit(doc, distance) for every live model of segment `s`, from its
  // postings, or from its forward entries and `dense` when they are freed.
  template <typename Emit>
  void ScanSegment(const PreparedQuery& query, const DenseQuery* dense, std::size_t s,
                   Emit&& emit) const;
  void CompactSegment(std::size_t s);

  uint32_t vocabulary_ = 0;
  KlDivergenceOptions options_;
  // Fitted once (see "Candidates"); then every model has its embedding.
  std::optional<HistogramEmbedding> embedding_;
  // The embeddings of the models with words, with the embedding.
  std::optional<CandidateIndex> candidates_;
  KlIndexStorage storage_;
  std::unique_ptr<ForwardStore> forward_;
  uint64_t live_entries_ = 0;  // forward entries of live models
  bool postings_ = true;       // false once freed (see "Storage")
  std::vector<std::unique_ptr<Segment>> segments_;
  absl::flat_hash_map<uint32_t, Location> locations_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_KL_INVERTED_INDEX_H_
