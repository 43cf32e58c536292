// A compact linear embedding of bag-of-features histograms, fitted to a
// collection, that proposes candidates for exact search (kl_inverted_index.h).
//
// What. e(x) = sum_k sqrt(x_k) P[k]: the square root of the histogram (its
// Hellinger form) projected on the `dimensions` principal axes P of the
// square roots of a sample of the collection. Euclidean distances between
// embeddings approximate Hellinger distances |sqrt x - sqrt y| within the
// principal subspace.
//
// Why these choices (measured on the real DLD-SIFT histograms of McGill
// articulated and PSB train, V = 2,000; bench/results/index.txt): the
// Hellinger ranking is a close proxy for the symmetric KL one (the exact KL
// top 10 lie in the Hellinger top 5 % for 99.9 % of PSB queries), and the
// principal axes keep it in few dimensions: 128 of them 99.2 %, where a
// random (Johnson-Lindenstrauss) projection of the same size keeps 88 %.
//
// Fitting: randomized SVD (Halko, Martinsson & Tropp 2011) of the centred
// sample matrix, never formed: a Gaussian range sketch of dimensions + 10
// columns, one power iteration with re-orthonormalisation (modified
// Gram-Schmidt), then the eigenvectors of the small sketch Gram matrix by
// cyclic Jacobi. Everything runs in double, in a fixed order, from a
// counter-based generator (SplitMix64): the same sample and seed give the same
// axes on every machine. Cost: about 4 x (sample non-zeros) x (dimensions + 10)
// multiply-adds plus the orthonormalisations (vocabulary x (dimensions + 10)^2),
// about 1 s for 2,048 histograms of 900 words at V = 2,000 and 3 s at
// V = 20,000 (1,700 words) on one core of the development machine.
//
// Immutable once fitted; Embed may be called from several threads at once.
#ifndef MESHSEEK_COMMON_SEARCH_HISTOGRAM_EMBEDDING_H_
#define MESHSEEK_COMMON_SEARCH_HISTOGRAM_EMBEDDING_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/search/sparse_histogram.h"

namespace meshseek {

class HistogramEmbedding {
 public:
  /// Fits the `dimensions` principal axes of the square roots of `sample`
  /// (histograms over `vocabulary` words, each valid; empty ones are
  /// skipped). InvalidArgument for dimensions outside [1, 1024], vocabulary 0,
  /// or a histogram over another vocabulary. With fewer independent
  /// histograms than dimensions the missing axes are zero (their coordinate
  /// is always 0), which only costs recall, never correctness.
  static absl::StatusOr<HistogramEmbedding> Fit(absl::Span<const SparseHistogram> sample,
                                                uint32_t vocabulary,
                                                int dimensions,
                                                uint64_t seed);

  int dimensions() const { return dimensions_; }
  uint32_t vocabulary() const { return vocabulary_; }

  /// e(x) into `out` (dimensions() floats) for the words and weights of a
  /// valid histogram over vocabulary() words.
  void Embed(absl::Span<const uint32_t> words, absl::Span<const float> weights, float* out) const;

 private:
  HistogramEmbedding(uint32_t vocabulary, int dimensions, std::vector<float> axes)
      : vocabulary_(vocabulary), dimensions_(dimensions), axes_(std::move(axes)) {}

  uint32_t vocabulary_ = 0;
  int dimensions_ = 0;
  // vocabulary x dimensions, row-major: row k is P[k], word k's contribution
  // per unit of sqrt(weight).
  std::vector<float> axes_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_HISTOGRAM_EMBEDDING_H_
