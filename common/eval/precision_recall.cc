#include "common/eval/precision_recall.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/eval/retrieval_metrics.h"

namespace meshseek {

absl::Status PrecisionRecallOptions::Validate() const {
  if (recall_steps < 1 || recall_steps > 1000) {
    return absl::InvalidArgumentError(
        absl::StrCat("recall_steps must be in [1, 1000], got ", recall_steps));
  }
  return absl::OkStatus();
}

std::vector<double> InterpolatedPrecision(const std::vector<bool>& relevant, int recall_steps) {
  // Precision only peaks at relevant ranks, so the j-th hit's precision
  // stands for every rank between it and the next hit.
  std::vector<double> at_hit;  // at_hit[j-1] = precision at the j-th hit
  for (std::size_t i = 0; i < relevant.size(); ++i) {
    if (relevant[i]) at_hit.push_back(static_cast<double>(at_hit.size() + 1) / (i + 1));
  }
  const std::size_t k = at_hit.size();
  // Running maximum from the back: best[j-1] = max precision at hits >= j.
  for (std::size_t j = k; j-- > 1;) at_hit[j - 1] = std::max(at_hit[j - 1], at_hit[j]);
  std::vector<double> curve(recall_steps + 1, 0.0);
  if (k == 0) return curve;
  for (int s = 0; s <= recall_steps; ++s) {
    // The fewest hits j with j/k >= s/steps, in integers so that a level such
    // as 0.5 is not missed by rounding.
    const std::size_t j = std::max<std::size_t>(1, (s * k + recall_steps - 1) / recall_steps);
    curve[s] = at_hit[j - 1];
  }
  return curve;
}

absl::StatusOr<PrecisionRecallCurves> ComputePrecisionRecall(
    const std::vector<std::string>& labels,
    const std::vector<float>& distances,
    const PrecisionRecallOptions& options) {
  if (absl::Status s = options.Validate(); !s.ok()) return s;
  MESHSEEK_ASSIGN_OR_RETURN(const QueryClasses classes, ClassifyQueries(labels, distances));
  const std::size_t n = labels.size();
  const std::vector<std::string>& names = classes.names;
  const std::vector<int>& label_id = classes.class_of;
  const std::vector<std::size_t>& queries = classes.queries;

  const int steps = options.recall_steps;
  std::vector<std::vector<double>> per_query(queries.size());
  ParallelFor(queries.size(), options.num_threads, [&](std::size_t qi) {
    const std::size_t q = queries[qi];
    const std::vector<std::pair<float, uint32_t>> ranking = RankOthers(distances, n, q);
    std::vector<bool> relevant(ranking.size());
    for (std::size_t r = 0; r < ranking.size(); ++r) {
      relevant[r] = label_id[ranking[r].second] == label_id[q];
    }
    per_query[qi] = InterpolatedPrecision(relevant, steps);
  });

  PrecisionRecallCurves curves;
  curves.queries = queries.size();
  for (int s = 0; s <= steps; ++s) curves.recall.push_back(static_cast<double>(s) / steps);
  curves.micro.assign(steps + 1, 0.0);
  curves.macro.assign(steps + 1, 0.0);
  std::vector<int> class_slot(names.size(), -1);
  std::vector<std::size_t> class_queries;
  for (std::size_t qi = 0; qi < queries.size(); ++qi) {
    const int c = label_id[queries[qi]];
    if (class_slot[c] < 0) {
      class_slot[c] = static_cast<int>(curves.per_class.size());
      curves.per_class.emplace_back(names[c], std::vector<double>(steps + 1, 0.0));
      class_queries.push_back(0);
    }
    std::vector<double>& sum = curves.per_class[class_slot[c]].second;
    for (int s = 0; s <= steps; ++s) {
      sum[s] += per_query[qi][s];
      curves.micro[s] += per_query[qi][s];
    }
    ++class_queries[class_slot[c]];
  }
  for (std::size_t slot = 0; slot < curves.per_class.size(); ++slot) {
    std::vector<double>& mean = curves.per_class[slot].second;
    for (int s = 0; s <= steps; ++s) {
      mean[s] /= class_queries[slot];
      curves.macro[s] += mean[s];
    }
  }
  for (int s = 0; s <= steps; ++s) {
    curves.micro[s] /= curves.queries;
    curves.macro[s] /= curves.per_class.size();
  }
  return curves;
}

}  // namespace meshseek
