// Precision-recall curves of leave-one-out retrieval, under the same protocol
// as retrieval_metrics.h (docs/design.md 3.2): every model of a class with C >= 3
// models that is not misc ("-1") is a query; its ranking is the other N-1
// models by ascending distance, ties broken by lower index; the relevant
// models are the k = C-1 others of its class.
//
// Each query's curve is the standard interpolated one (Manning, Raghavan and
// Schuetze, "Introduction to Information Retrieval", section 8.4; the PSB
// tools plot the same): at recall level r, the highest precision reached at
// any rank where recall >= r,
//   P_interp(r) = max { hits(i) / i : hits(i) / k >= r },
// with hits(i) the relevant models among the top i. Interpolation makes the
// curve non-increasing and defined at every level (all N-1 models are ranked,
// so recall 1 is always reached). The curves are sampled at the levels
// 0, 1/S, 2/S, ..., 1 (S = recall_steps; 20 gives the usual 0, 0.05, ..., 1)
// and averaged like the scalar metrics: micro over queries, macro over classes
// of each class's mean over its queries.
#ifndef MESHSEEK_COMMON_EVAL_PRECISION_RECALL_H_
#define MESHSEEK_COMMON_EVAL_PRECISION_RECALL_H_

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace meshseek {

struct PrecisionRecallOptions {
  /// Number of intervals between recall 0 and 1; the curves have
  /// recall_steps + 1 points. In [1, 1000].
  int recall_steps = 20;
  /// Threads over queries (<= 0: all cores); the result does not depend on it.
  int num_threads = 1;

  absl::Status Validate() const;
};

struct PrecisionRecallCurves {
  /// The recall levels, 0 to 1 in recall_steps equal steps.
  std::vector<double> recall;
  /// Interpolated precision at each level, fractions in [0, 1]: the mean over
  /// queries (micro) and over classes of the class means (macro).
  std::vector<double> micro;
  std::vector<double> macro;
  /// Per query class, the mean over its queries, in order of the class's
  /// first query (RetrievalMetrics::per_class's order).
  std::vector<std::pair<std::string, std::vector<double>>> per_class;
  std::size_t queries = 0;
};

// The interpolated precision of one ranking at the levels 0, 1/steps, ..., 1.
// `relevant[i]` says whether the model at rank i+1 is relevant; at least one
// must be. (The building block, exposed for tests and other rankings.)
std::vector<double> InterpolatedPrecision(const std::vector<bool>& relevant, int recall_steps);

// The curves of the leave-one-out ranking of `distances` (N x N row-major,
// N = labels.size(); the diagonal is ignored; infinities allowed).
// Errors (InvalidArgument), as EvaluateRetrieval's: invalid options, no
// labels, an empty label, distances.size() != N*N, a NaN distance (naming row
// and column), no query at all.
absl::StatusOr<PrecisionRecallCurves> ComputePrecisionRecall(
    const std::vector<std::string>& labels,
    const std::vector<float>& distances,
    const PrecisionRecallOptions& options = {});

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_PRECISION_RECALL_H_
