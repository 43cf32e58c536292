// Symmetric Kullback-Leibler divergence between bag-of-features histograms,
// the distance of the paper (Ohishi & Ohbuchi 2013, eq. 1; docs/design.md 2.7):
//
//   D(x, y) = sum_k (x_k - y_k) ln(x_k / y_k)  =  KL(x || y) + KL(y || x).
//
// Zero bins. ln(x_k / y_k) is undefined where a bin is empty, and BoF
// histograms of ~2,000 descriptors over V = 500..5,000 words have many empty
// bins. Rule: add `epsilon` to every bin, then renormalise,
//
//   x'_k = (x_k + epsilon) / (sum_j x_j + V epsilon),
//
// which is (x_k + eps) / (1 + V eps) for a normalised x, and compute D on x' and
// y'. (FLANN's KL distance instead skips bins that are zero in either vector and
// is not symmetric, so meshseek does not use it: docs/design.md 2.7.) With this rule every term
// (x'_k - y'_k)(ln x'_k - ln y'_k) is >= 0, so D >= 0, D(x, x) = 0, and a word
// used by one model and not by the other costs about a ln(a / epsilon) for its
// mass a instead of infinity. Epsilon is the knob the paper leaves open (docs/design.md 2.8):
// smaller weighs "word present in one model only" more against "word used
// with different frequencies". Default 1e-10, measured on McGill articulated
// (DLD-SIFT, V = 1,000..3,000): first tier rose monotonically as epsilon fell
// from 1e-3 (-2.2 points against 1e-6) through 1e-6 to 1e-10 (+0.3..0.5
// points); on PSB train 1e-6 and 1e-10 tie. It is far below one descriptor's
// mass (about 1/3,000), so non-empty bins keep their values, and an unmatched
// single-descriptor bin costs about 3e-4 ln(3e6) = 5e-3.
//
// Numerics and speed. Each histogram is prepared once: x' and ln x' in double.
// A pair is then one pass of subtract, subtract, multiply, add over the bins,
// summed in double in a fixed lane order, with no logarithm. The all-pairs path
// computes each unordered pair once and mirrors it, and since
// (x' - y')(ln x' - ln y') and (y' - x')(ln y' - ln x') are the same IEEE
// product, every path gives the same value for a pair in either order: the
// matrix is exactly symmetric and equals the pairwise and query paths bit for
// bit. Distances are returned as float (the distance-matrix format is float32).
#ifndef MESHSEEK_COMMON_BOF_KL_DIVERGENCE_H_
#define MESHSEEK_COMMON_BOF_KL_DIVERGENCE_H_

#include <cstddef>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"

namespace meshseek {

struct KlDivergenceOptions {
  /// Mass added to every bin before renormalising (the zero-bin rule above).
  double epsilon = 1e-10;
  /// An input histogram must sum to 1 within this: anything else (raw counts,
  /// a truncated vector) is a caller's bug, not a distribution.
  double sum_tolerance = 1e-3;

  /// InvalidArgument naming the bad field and its value.
  absl::Status Validate() const;
};

/// A set of histograms prepared for fast divergence computations (x' and
/// ln x' stored in double, 16 bytes per bin and histogram: 16 MB for 1,000
/// models at V = 1,000). Immutable once made; const methods are thread-safe.
class KlHistogramSet {
 public:
  /// Validates and prepares `histograms`: at least one, all of the same
  /// non-zero length, entries finite and >= 0, each summing to 1 within
  /// options.sum_tolerance. InvalidArgument names the histogram, bin and value
  /// (e.g. "histogram 3 sums to 0.82, expected 1 within 0.001").
  static absl::StatusOr<KlHistogramSet> Create(const std::vector<std::vector<float>>& histograms,
                                               const KlDivergenceOptions& options = {});

  /// Number of histograms N.
  std::size_t size() const { return size_; }
  /// Number of bins V.
  std::size_t bins() const { return bins_; }

  /// D between histograms i and j (both < size()).
  double Divergence(std::size_t i, std::size_t j) const;

  /// All pairs: N x N row-major, entry i * N + j = D(i, j); zero diagonal,
  /// exactly symmetric, each pair computed once. Up to `num_threads` threads
  /// (<= 0: all cores); the result does not depend on the thread count.
  std::vector<float> DistanceMatrix(int num_threads) const;

  /// D from `query` (validated like the members) to every member, in order.
  absl::StatusOr<std::vector<float>> DistancesFrom(absl::Span<const float> query,
                                                   int num_threads) const;

 private:
  KlHistogramSet(KlDivergenceOptions options, std::size_t bins);
  // Validates `histogram` and appends its x' and ln x'; `name` names it in errors.
  absl::Status Add(absl::Span<const float> histogram, absl::string_view name);

  KlDivergenceOptions options_;
  std::size_t size_ = 0;
  std::size_t bins_ = 0;
  std::vector<double> smoothed_;      // size_ x bins_: x'
  std::vector<double> log_smoothed_;  // size_ x bins_: ln x'
};

/// D(x, y) for one pair; validation as in KlHistogramSet::Create (errors call
/// x "histogram 0" and y "histogram 1").
absl::StatusOr<double> SymmetricKlDivergence(absl::Span<const float> x,
                                             absl::Span<const float> y,
                                             const KlDivergenceOptions& options = {});

/// All-pairs distance matrix of `histograms` (see KlHistogramSet::DistanceMatrix).
absl::StatusOr<std::vector<float>> SymmetricKlDistanceMatrix(
    const std::vector<std::vector<float>>& histograms,
    const KlDivergenceOptions& options,
    int num_threads);

/// Distances from `query` to each of `database`, in order (the ranking path).
/// For repeated queries against one database, create a KlHistogramSet once.
absl::StatusOr<std::vector<float>> SymmetricKlDistances(
    absl::Span<const float> query,
    const std::vector<std::vector<float>>& database,
    const KlDivergenceOptions& options,
    int num_threads);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BOF_KL_DIVERGENCE_H_
