// Leave-one-out retrieval statistics (docs/design.md 3.2), defined exactly as the
// independent reference evaluator psb_eval.py (outside the repository; bench/
// scripts run it on every matrix) computes them, which in turn follow
// the Princeton Shape Benchmark's psbTable (Shilane et al., "The Princeton
// Shape Benchmark", SMI 2004).
//
// Every model q whose class has C >= 3 models and is not misc ("-1") is a
// query. Its ranking is the other N-1 models by ascending distance from q
// (row q of the matrix), ties broken by lower index. With k = C-1 relevant
// models and "hit" meaning a model of q's class:
//   NN       1 if the rank-1 model is a hit, else 0
//   FT       hits in the top k, / k                     (first tier)
//   ST       hits in the top 2k, / k                    (second tier)
//   E        F1 of precision and recall over the top t = min(32, N-1):
//            P = h/t, R = h/k with h hits there, E = 2PR/(P+R) = 2h/(t+k)
//   DCG      sum over hits at rank r of (1 if r = 1 else 1/log2 r), divided
//            by the same sum for the ideal ranking (all k hits first)
//   RP_excl  R-precision with the query left out: hits in the top k, / k (= FT)
//   RP_incl  R-precision counting the query as its own first result:
//            (1 + hits in the top k) / C
// The paper meshseek reproduces reports "R-precision" without saying which of
// the last two it means, so both are kept.
// Micro averages are over queries; macro averages are the mean over classes of
// each class's mean over its queries. Models of non-query classes stay in the
// database (they are ranked, and count as misses).
#ifndef MESHSEEK_COMMON_EVAL_RETRIEVAL_METRICS_H_
#define MESHSEEK_COMMON_EVAL_RETRIEVAL_METRICS_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/base/json.h"

namespace meshseek {

// One query's scores, or an average of them. All are fractions in [0, 1]
// (reports multiply by 100).
struct RetrievalScores {
  double nn = 0;           // nearest neighbour
  double first_tier = 0;   // FT
  double second_tier = 0;  // ST
  double e_measure = 0;    // E (F1 at 32)
  double dcg = 0;          // normalised discounted cumulative gain
  double rp_excl = 0;      // R-precision, query excluded
  double rp_incl = 0;      // R-precision, query counted as its own first result
};

struct QueryScores {
  std::size_t model = 0;  // the query's index in the matrix / label order
  RetrievalScores scores;
};

struct RetrievalMetrics {
  std::size_t queries = 0;  // models evaluated as queries
  std::size_t classes = 0;  // classes with queries (C >= 3, not misc)
  RetrievalScores micro;    // mean over queries
  RetrievalScores macro;    // mean over classes of the per-class means
  // Per query class: its name and the mean over its queries, in order of the
  // class's first model (psb_eval.py's order).
  std::vector<std::pair<std::string, RetrievalScores>> per_class;
  std::vector<QueryScores> per_query;  // in model order
};

// A metric's key (as metrics.json and psb_eval.py name it) and its field, in
// the reports' column order: NN, FT, ST, E, DCG, RP_excl, RP_incl.
struct ScoreColumn {
  const char* key;
  double RetrievalScores::*field;
};
absl::Span<const ScoreColumn> ScoreColumns();

// The classes of a labelled N x N distance matrix and which models are
// queries (docs/design.md 3.2: not misc, of a class with more than 2 models):
// what every evaluation of a ranking starts from.
struct QueryClasses {
  std::vector<std::string> names;    // classes in order of their first model
  std::vector<std::size_t> sizes;    // models per class
  std::vector<int> class_of;         // per model, an index into names
  std::vector<std::size_t> queries;  // query models, ascending
};
// Errors as EvaluateRetrieval's below.
absl::StatusOr<QueryClasses> ClassifyQueries(const std::vector<std::string>& labels,
                                             const std::vector<float>& distances);

// Model q's ranking of the other models of an N x N matrix: (distance,
// index) pairs, nearest first, ties by index (psb_eval.py's rule). Only the
// first `top` are sorted (and returned) when fewer are wanted.
std::vector<std::pair<float, uint32_t>> RankOthers(const std::vector<float>& distances,
                                                   std::size_t n,
                                                   std::size_t q,
                                                   std::size_t top = SIZE_MAX);

// Evaluates leave-one-out retrieval. `labels[i]` is model i's class and
// `distances` the N x N row-major matrix (entry i*N+j = distance from query i
// to model j, N = labels.size(); the diagonal is ignored). Infinite distances
// are allowed. O(N^2 log N): each query sorts the other models. Queries are
// spread over `num_threads` threads (<= 0: all cores); the result does not
// depend on the thread count.
// Errors (InvalidArgument): no labels, an empty label (naming the model),
// distances.size() != N*N (both sizes named), a NaN distance (naming row and
// column, 0-based), no query at all (every class has <= 2 models or is misc).
absl::StatusOr<RetrievalMetrics> EvaluateRetrieval(const std::vector<std::string>& labels,
                                                   const std::vector<float>& distances,
                                                   int num_threads = 1);

// The summary as psb_eval.py prints it, in percent with one decimal:
//
//   255 queries in 10 classes (percent)
//                 NN       FT       ST        E      DCG  RP_excl  RP_incl
//     micro     93.3     71.2     84.5     51.0     90.1     71.2     72.2
//     macro     ...
std::string FormatMetricsTable(const RetrievalMetrics& metrics);

// The metrics as JSON, values in percent (as psb_eval.py --json writes them,
// plus the per-class means):
//   {"queries": Q, "classes": C,
//    "micro": {"NN", "FT", "ST", "E", "DCG", "RP_excl", "RP_incl"},
//    "macro": {...same keys...},
//    "per_class": {"<class>": {...same keys...}, ...}}
Json MetricsToJson(const RetrievalMetrics& metrics);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_RETRIEVAL_METRICS_H_
