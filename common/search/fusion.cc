#include "common/search/fusion.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace meshseek {

namespace {

// i * n / count for i < min(n, count): evenly spread, increasing.
std::vector<std::size_t> EvenSample(std::size_t n, std::size_t most) {
  const std::size_t count = std::min(n, most);
  std::vector<std::size_t> at(count);
  for (std::size_t i = 0; i < count; ++i) at[i] = i * n / count;
  return at;
}

}  // namespace

std::vector<std::size_t> ScaleSampleRows(std::size_t n) { return EvenSample(n, kScaleRows); }
std::vector<std::size_t> ScaleSampleColumns(std::size_t n) { return EvenSample(n, kScaleColumns); }

void DistanceScale::AddRow(std::size_t self, absl::Span<const float> row) {
  for (std::size_t j = 0; j < row.size(); ++j) {
    if (j == self || !std::isfinite(row[j])) continue;
    sum_ += row[j];
    ++count_;
  }
}

double DistanceScale::Scale() const {
  if (count_ == 0 || !(sum_ > 0.0)) return 1.0;
  return sum_ / static_cast<double>(count_);
}

absl::StatusOr<std::vector<double>> FusionFactors(absl::Span<const double> weights,
                                                  absl::Span<const double> scales) {
  if (weights.size() != scales.size() || weights.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("fusion: ", weights.size(), " weights for ", scales.size(), " methods"));
  }
  double total = 0.0;
  for (std::size_t m = 0; m < weights.size(); ++m) {
    if (!std::isfinite(weights[m]) || weights[m] < 0.0) {
      return absl::InvalidArgumentError(
          absl::StrCat("fusion: weight ", m + 1, " is ", weights[m], " (must be >= 0)"));
    }
    if (!std::isfinite(scales[m]) || !(scales[m] > 0.0)) {
      return absl::InvalidArgumentError(
          absl::StrCat("fusion: scale ", m + 1, " is ", scales[m], " (must be > 0)"));
    }
    total += weights[m];
  }
  if (!(total > 0.0)) return absl::InvalidArgumentError("fusion: every weight is 0");
  std::vector<double> factors(weights.size());
  for (std::size_t m = 0; m < weights.size(); ++m) factors[m] = weights[m] / (scales[m] * total);
  return factors;
}

void FuseRows(absl::Span<const absl::Span<const float>> rows,
              absl::Span<const double> factors,
              absl::Span<float> out) {
  for (std::size_t j = 0; j < out.size(); ++j) {
    double sum = 0.0;
    for (std::size_t m = 0; m < rows.size(); ++m) {
      if (factors[m] != 0.0) sum += factors[m] * rows[m][j];
    }
    out[j] = static_cast<float>(sum);
  }
}

}  // namespace meshseek
