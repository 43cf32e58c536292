#include "common/bof/kl_divergence.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

// Rows of the all-pairs matrix per ParallelFor item: each column histogram is
// loaded once per block and reused for every row of it.
constexpr std::size_t kRowsPerBlock = 16;
// Database histograms per ParallelFor item in the query path.
constexpr std::size_t kColumnsPerTask = 64;

// Two double lanes: one SSE2 register (see nearest_centroid.cc for why a
// generic vector type rather than plain loops).
typedef double Double2 __attribute__((vector_size(16)));

// sum_k (p_k - q_k)(lp_k - lq_k), in four lanes reduced in a fixed order.
double PairDivergence(
    const double* p, const double* lp, const double* q, const double* lq, std::size_t bins) {
  Double2 acc0 = {}, acc1 = {};
  std::size_t k = 0;
  for (; k + 4 <= bins; k += 4) {
    Double2 p0, p1, lp0, lp1, q0, q1, lq0, lq1;
    std::memcpy(&p0, p + k, 16);
    std::memcpy(&p1, p + k + 2, 16);
    std::memcpy(&lp0, lp + k, 16);
    std::memcpy(&lp1, lp + k + 2, 16);
    std::memcpy(&q0, q + k, 16);
    std::memcpy(&q1, q + k + 2, 16);
    std::memcpy(&lq0, lq + k, 16);
    std::memcpy(&lq1, lq + k + 2, 16);
    acc0 += (p0 - q0) * (lp0 - lq0);
    acc1 += (p1 - q1) * (lp1 - lq1);
  }
  double tail = 0.0;
  for (; k < bins; ++k) tail += (p[k] - q[k]) * (lp[k] - lq[k]);
  return ((acc0[0] + acc0[1]) + (acc1[0] + acc1[1])) + tail;
}

}  // namespace

absl::Status KlDivergenceOptions::Validate() const {
  if (!(epsilon > 0.0 && epsilon < 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("KlDivergenceOptions: epsilon must be in (0, 1), got ", epsilon));
  }
  if (!(sum_tolerance >= 0.0 && sum_tolerance < 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("KlDivergenceOptions: sum_tolerance must be in [0, 1), got ", sum_tolerance));
  }
  return absl::OkStatus();
}

KlHistogramSet::KlHistogramSet(KlDivergenceOptions options, std::size_t bins)
    : options_(options), bins_(bins) {}

absl::Status KlHistogramSet::Add(absl::Span<const float> histogram, absl::string_view name) {
  if (histogram.size() != bins_) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " has ", histogram.size(), " bins, expected ", bins_));
  }
  double sum = 0.0;
  for (std::size_t k = 0; k < bins_; ++k) {
    if (!(std::isfinite(histogram[k]) && histogram[k] >= 0.0f)) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ", bin ", k, " is ", histogram[k], " (must be finite and >= 0)"));
    }
    sum += histogram[k];
  }
  if (std::fabs(sum - 1.0) > options_.sum_tolerance) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " sums to ", sum, ", expected 1 within ", options_.sum_tolerance));
  }
  const double eps = options_.epsilon;
  const double total = sum + static_cast<double>(bins_) * eps;
  for (std::size_t k = 0; k < bins_; ++k) {
    const double smoothed = (static_cast<double>(histogram[k]) + eps) / total;
    smoothed_.push_back(smoothed);
    log_smoothed_.push_back(std::log(smoothed));
  }
  ++size_;
  return absl::OkStatus();
}

absl::StatusOr<KlHistogramSet> KlHistogramSet::Create(
    const std::vector<std::vector<float>>& histograms, const KlDivergenceOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  if (histograms.empty()) return absl::InvalidArgumentError("no histograms given");
  if (histograms[0].empty()) return absl::InvalidArgumentError("histogram 0 has 0 bins");
  KlHistogramSet set(options, histograms[0].size());
  set.smoothed_.reserve(histograms.size() * set.bins_);
  set.log_smoothed_.reserve(histograms.size() * set.bins_);
  for (std::size_t i = 0; i < histograms.size(); ++i) {
    MESHSEEK_RETURN_IF_ERROR(set.Add(histograms[i], absl::StrCat("histogram ", i)));
  }
  return set;
}

double KlHistogramSet::Divergence(std::size_t i, std::size_t j) const {
  return PairDivergence(&smoothed_[i * bins_],
                        &log_smoothed_[i * bins_],
                        &smoothed_[j * bins_],
                        &log_smoothed_[j * bins_],
                        bins_);
}

std::vector<float> KlHistogramSet::DistanceMatrix(int num_threads) const {
  const std::size_t n = size_;
  std::vector<float> matrix(n * n, 0.0f);
  const std::size_t blocks = (n + kRowsPerBlock - 1) / kRowsPerBlock;
  // Entry (r, s) is written only by the block holding min(r, s): no races.
  ParallelFor(blocks, num_threads, [&](std::size_t block) {
    const std::size_t begin = block * kRowsPerBlock;
    const std::size_t end = std::min(n, begin + kRowsPerBlock);
    for (std::size_t j = begin + 1; j < n; ++j) {
      for (std::size_t i = begin; i < std::min(end, j); ++i) {
        const float d = static_cast<float>(Divergence(i, j));
        matrix[i * n + j] = d;
        matrix[j * n + i] = d;
      }
    }
  });
  return matrix;
}

absl::StatusOr<std::vector<float>> KlHistogramSet::DistancesFrom(absl::Span<const float> query,
                                                                 int num_threads) const {
  KlHistogramSet prepared(options_, bins_);
  MESHSEEK_RETURN_IF_ERROR(prepared.Add(query, "query"));
  std::vector<float> distances(size_);
  const std::size_t tasks = (size_ + kColumnsPerTask - 1) / kColumnsPerTask;
  ParallelFor(tasks, num_threads, [&](std::size_t task) {
    const std::size_t end = std::min(size_, (task + 1) * kColumnsPerTask);
    for (std::size_t j = task * kColumnsPerTask; j < end; ++j) {
      distances[j] = static_cast<float>(PairDivergence(prepared.smoothed_.data(),
                                                       prepared.log_smoothed_.data(),
                                                       &smoothed_[j * bins_],
                                                       &log_smoothed_[j * bins_],
                                                       bins_));
    }
  });
  return distances;
}

absl::StatusOr<double> SymmetricKlDivergence(absl::Span<const float> x,
                                             absl::Span<const float> y,
                                             const KlDivergenceOptions& options) {
  MESHSEEK_ASSIGN_OR_RETURN(const KlHistogramSet set,
                            KlHistogramSet::Create({std::vector<float>(x.begin(), x.end()),
                                                    std::vector<float>(y.begin(), y.end())},
                                                   options));
  return set.Divergence(0, 1);
}

absl::StatusOr<std::vector<float>> SymmetricKlDistanceMatrix(
    const std::vector<std::vector<float>>& histograms,
    const KlDivergenceOptions& options,
    int num_threads) {
  MESHSEEK_ASSIGN_OR_RETURN(const KlHistogramSet set, KlHistogramSet::Create(histograms, options));
  return set.DistanceMatrix(num_threads);
}

absl::StatusOr<std::vector<float>> SymmetricKlDistances(
    absl::Span<const float> query,
    const std::vector<std::vector<float>>& database,
    const KlDivergenceOptions& options,
    int num_threads) {
  MESHSEEK_ASSIGN_OR_RETURN(const KlHistogramSet set, KlHistogramSet::Create(database, options));
  return set.DistancesFrom(query, num_threads);
}

}  // namespace meshseek
