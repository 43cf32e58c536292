#include "common/search/sparse_histogram.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace meshseek {

absl::Status SparseHistogram::Validate(absl::string_view name, double sum_tolerance) const {
  if (vocabulary == 0) {
    return absl::InvalidArgumentError(absl::StrCat(name, " has vocabulary size 0"));
  }
  if (vocabulary > kMaxVocabulary) {
    return absl::InvalidArgumentError(absl::StrCat(name, " has vocabulary size ", vocabulary,
                                                   ", more than the limit ", kMaxVocabulary));
  }
  if (words.size() != weights.size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        name, " has ", words.size(), " words but ", weights.size(), " weights"));
  }
  if (words.size() > vocabulary) {
    return absl::InvalidArgumentError(absl::StrCat(
        name, " has ", words.size(), " words for a vocabulary of ", vocabulary));
  }
  if (words.empty()) return absl::OkStatus();
  double sum = 0.0;
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (words[i] >= vocabulary || (i > 0 && words[i] <= words[i - 1])) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ", entry ", i, ": word ", words[i],
                       " is out of range or order (vocabulary ", vocabulary,
                       i > 0 ? absl::StrCat(", previous word ", words[i - 1]) : "", ")"));
    }
    if (!(std::isfinite(weights[i]) && weights[i] > 0.0f)) {
      return absl::InvalidArgumentError(absl::StrCat(
          name, ", word ", words[i], ": weight ", weights[i], " (must be finite and > 0)"));
    }
    sum += weights[i];
  }
  if (!(std::fabs(sum - 1.0) <= sum_tolerance)) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " sums to ", sum, ", expected 1 within ", sum_tolerance));
  }
  return absl::OkStatus();
}

SparseHistogram SparseFromDense(absl::Span<const float> dense) {
  SparseHistogram sparse;
  sparse.vocabulary = static_cast<uint32_t>(dense.size());
  for (std::size_t k = 0; k < dense.size(); ++k) {
    if (dense[k] == 0.0f) continue;
    sparse.words.push_back(static_cast<uint32_t>(k));
    sparse.weights.push_back(dense[k]);
  }
  return sparse;
}

std::vector<float> DenseFromSparse(const SparseHistogram& sparse) {
  std::vector<float> dense(sparse.vocabulary, 0.0f);
  for (std::size_t i = 0; i < sparse.words.size(); ++i) dense[sparse.words[i]] = sparse.weights[i];
  return dense;
}

}  // namespace meshseek
