// Weighting of bag-of-features histograms before they are compared:
//  - inverse document frequency (tf-idf): word k's bin is multiplied by
//    idf_k = ln((1 + N) / (1 + df_k)) + 1, df_k the number of the
//    collection's N models whose histogram has word k (the smoothed form:
//    never zero, so no histogram loses all its mass to words every model
//    has). Words common to every model say little about which model it is;
//  - power normalisation: every bin raised to `power` (0.5: square root, the
//    Hellinger form), which damps words a model repeats (a flat region seen
//    by hundreds of patches) against the rarer ones.
// Each weighted histogram is renormalised to sum 1, so the symmetric KL
// divergence (and its zero-bin rule) applies unchanged.
//
// Measured on the development sets (README "Ablation", bench/results/weighting.txt):
// neither helps KL overall, so both are off by default.
#ifndef MESHSEEK_COMMON_BOF_HISTOGRAM_WEIGHTING_H_
#define MESHSEEK_COMMON_BOF_HISTOGRAM_WEIGHTING_H_

#include <vector>

#include "absl/status/status.h"
#include "absl/types/span.h"

namespace meshseek {

struct HistogramWeighting {
  /// Multiply every bin by its word's inverse document frequency over the
  /// collection (needs the whole collection: InverseDocumentFrequencies).
  bool idf = false;
  /// Exponent of every bin, in (0, 1]; 1 leaves the bins as they are.
  double power = 1.0;

  bool enabled() const { return idf || power != 1.0; }
  /// InvalidArgument naming the bad field and its value.
  absl::Status Validate() const;
};

// idf_k over the non-empty histograms of a collection (all of one length V;
// empty ones are models without features and count for nothing): V values.
// Empty when every histogram is empty.
std::vector<float> InverseDocumentFrequencies(const std::vector<std::vector<float>>& histograms);

// Weights one histogram in place (`idf` empty: no idf; otherwise of the
// histogram's length) and renormalises it to sum 1. A histogram of zero
// mass is left as it is. InvalidArgument for an idf of another length.
absl::Status WeightHistogram(const HistogramWeighting& weighting,
                             absl::Span<const float> idf,
                             absl::Span<float> histogram);

// Weights every histogram of a collection: idf from the collection itself
// when weighting.idf. Empty histograms stay empty.
absl::Status WeightCollection(const HistogramWeighting& weighting,
                              std::vector<std::vector<float>>* histograms);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BOF_HISTOGRAM_WEIGHTING_H_
