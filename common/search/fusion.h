// Fusing the distances of several methods into one ranking (late fusion).
//
// Methods' distances live on unrelated scales (symmetric KL of BoF
// histograms in the tens, LFD's summed L1 in the thousands), so each is first
// divided by its scale in the collection, the mean of its finite distances
// between different models, and the fused distance is the weighted mean
//
//   d(q, x) = sum_m w_m d_m(q, x) / s_m / sum_m w_m.
//
// One scale per method and collection (not per query) keeps the fused
// distance a property of the pair: shards can rank their own models and merge
// exactly, and a model's fused row in eval equals its fused query. On the
// development sets this measured as well as per-query normalisations (by the
// query's mean, its z-score or its k nearest: bench/results/fusion.txt).
//
// The scale is estimated from a fixed sample of rows, evenly spread over the
// collection order (ScaleSampleRows), so that the in-process pipeline and
// the services, which see the rows in the same order, compute the same
// double. A model at distance +inf (no features) stays at +inf.
#ifndef MESHSEEK_COMMON_SEARCH_FUSION_H_
#define MESHSEEK_COMMON_SEARCH_FUSION_H_

#include <cstddef>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"

namespace meshseek {

/// Rows sampled to estimate a method's scale: i * n / kScaleRows for
/// i < min(n, kScaleRows), increasing.
inline constexpr std::size_t kScaleRows = 256;
std::vector<std::size_t> ScaleSampleRows(std::size_t n);
/// Columns of those rows sampled in a collection of more than
/// kScaleColumns models (the services' builds: each sampled distance is an
/// exact one from the forward index, and a whole row of a 100,000-model
/// BF-DSIFT collection without postings reads 4 GB): i * n / kScaleColumns
/// for i < kScaleColumns; every column up to kScaleColumns models, so every
/// development set's scales, and with them its matrices, are those of whole
/// rows.
inline constexpr std::size_t kScaleColumns = 8192;
std::vector<std::size_t> ScaleSampleColumns(std::size_t n);

/// Accumulates the mean of a method's finite off-diagonal distances over
/// the sampled rows, in the order rows are added (the order of
/// ScaleSampleRows).
class DistanceScale {
 public:
  /// `row`: model `self`'s distances to every model (or to the sampled
  /// columns, `self` its position among them or any larger value).
  void AddRow(std::size_t self, absl::Span<const float> row);
  /// The mean; 1 when no finite off-diagonal distance was seen or it is 0
  /// (every model alike: nothing to normalise).
  double Scale() const;

 private:
  double sum_ = 0.0;
  std::size_t count_ = 0;
};

/// The factors w_m / (s_m sum_m w_m) by which each method's distances are
/// multiplied. InvalidArgument for sizes that differ, a negative, NaN or
/// infinite weight, weights summing to 0, or a scale that is not positive.
absl::StatusOr<std::vector<double>> FusionFactors(absl::Span<const double> weights,
                                                  absl::Span<const double> scales);

/// out[j] = sum_m factors[m] rows[m][j] in double, members in order; a member
/// with factor 0 is skipped (so its +inf cannot make NaN).
void FuseRows(absl::Span<const absl::Span<const float>> rows,
              absl::Span<const double> factors,
              absl::Span<float> out);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_FUSION_H_
