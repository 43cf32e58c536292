#include "common/bof/histogram_weighting.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"

namespace meshseek {

absl::Status HistogramWeighting::Validate() const {
  if (!(power > 0.0 && power <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("HistogramWeighting: power must be in (0, 1], got ", power));
  }
  return absl::OkStatus();
}

std::vector<float> InverseDocumentFrequencies(const std::vector<std::vector<float>>& histograms) {
  std::vector<double> df;
  double n = 0;
  for (const std::vector<float>& h : histograms) {
    if (h.empty()) continue;
    if (df.empty()) df.assign(h.size(), 0.0);
    n += 1;
    for (std::size_t k = 0; k < h.size() && k < df.size(); ++k) df[k] += h[k] > 0;
  }
  std::vector<float> idf(df.size());
  for (std::size_t k = 0; k < df.size(); ++k) {
    idf[k] = static_cast<float>(std::log((1 + n) / (1 + df[k])) + 1);
  }
  return idf;
}

absl::Status WeightHistogram(const HistogramWeighting& weighting,
                             absl::Span<const float> idf,
                             absl::Span<float> histogram) {
  if (!idf.empty() && idf.size() != histogram.size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "histogram of ", histogram.size(), " words weighted by an idf of ", idf.size()));
  }
  double sum = 0;
  for (std::size_t k = 0; k < histogram.size(); ++k) {
    if (!(histogram[k] > 0)) continue;
    double value = histogram[k];
    if (!idf.empty()) value *= idf[k];
    if (weighting.power != 1.0) value = std::pow(value, weighting.power);
    histogram[k] = static_cast<float>(value);
    sum += histogram[k];
  }
  if (sum > 0) {
    for (float& x : histogram) x = static_cast<float>(x / sum);
  }
  return absl::OkStatus();
}

absl::Status WeightCollection(const HistogramWeighting& weighting,
                              std::vector<std::vector<float>>* histograms) {
  MESHSEEK_RETURN_IF_ERROR(weighting.Validate());
  if (!weighting.enabled()) return absl::OkStatus();
  const std::vector<float> idf =
      weighting.idf ? InverseDocumentFrequencies(*histograms) : std::vector<float>();
  for (std::size_t i = 0; i < histograms->size(); ++i) {
    std::vector<float>& h = (*histograms)[i];
    if (h.empty()) continue;
    if (absl::Status s = WeightHistogram(weighting, idf, absl::MakeSpan(h)); !s.ok()) {
      return absl::Status(s.code(), absl::StrCat("model ", i, ": ", s.message()));
    }
  }
  return absl::OkStatus();
}

}  // namespace meshseek
