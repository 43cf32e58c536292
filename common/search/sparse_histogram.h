// A bag-of-features histogram stored sparsely: the words a model uses and
// their weights. Real histograms at V = 2,000 use about half the words and
// at V = 20,000 a few percent, so the index keeps only these pairs
// (docs/design.md 2.7a).
#ifndef MESHSEEK_COMMON_SEARCH_SPARSE_HISTOGRAM_H_
#define MESHSEEK_COMMON_SEARCH_SPARSE_HISTOGRAM_H_

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"

namespace meshseek {

/// Largest vocabulary a histogram may declare. meshseek trains up to 50,000
/// words; the bound keeps a hostile size from costing memory (the index keeps
/// per-word bookkeeping) and lets the index name words and weights in 16 bits.
inline constexpr uint32_t kMaxVocabulary = 1 << 16;

struct SparseHistogram {
  /// Vocabulary size V: every word is less than it.
  uint32_t vocabulary = 0;
  /// Strictly increasing word indices.
  std::vector<uint32_t> words;
  /// Their weights, > 0 and finite, summing to 1 (words.size() entries). A
  /// histogram without words is a model without local features.
  std::vector<float> weights;

  bool empty() const { return words.empty(); }

  /// InvalidArgument naming `name`, the position and the value: vocabulary
  /// 0 or above kMaxVocabulary, size mismatch, a word out of range or out of order, a weight that is
  /// not finite and > 0, or weights not summing to 1 within `sum_tolerance`
  /// (an empty histogram is valid).
  absl::Status Validate(absl::string_view name, double sum_tolerance) const;
};

/// The non-zero bins of a dense histogram (which must have at most 2^32 - 1
/// bins; the dense form's length is the vocabulary). Zero bins are dropped,
/// others kept as they are: validate the result.
SparseHistogram SparseFromDense(absl::Span<const float> dense);

/// The dense form: vocabulary entries, zero where no word is stored.
std::vector<float> DenseFromSparse(const SparseHistogram& sparse);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_SPARSE_HISTOGRAM_H_
