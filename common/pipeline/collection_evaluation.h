// Evaluating a collection under the paper's protocol (docs/design.md 3.3): every
// model a query against all others, codebooks learnt from the collection's
// own features. Each method of the collection is evaluated by
// EvaluateMethod (retrieval_pipeline.h); their matrices are then combined
// into the collection's ranking as CollectionOptions says: one method's own
// distances, or each rescaled, fused and re-ranked (CombineMethodDistances,
// the same arithmetic as the services' rows).
#ifndef MESHSEEK_COMMON_PIPELINE_COLLECTION_EVALUATION_H_
#define MESHSEEK_COMMON_PIPELINE_COLLECTION_EVALUATION_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/base/json.h"
#include "common/eval/manifest.h"
#include "common/eval/retrieval_metrics.h"
#include "common/pipeline/collection_options.h"
#include "common/pipeline/retrieval_pipeline.h"

namespace meshseek {

struct CollectionEvaluation {
  std::vector<ManifestEntry> models;  // input order = matrix order
  /// One per method of the collection, in its order.
  std::vector<MethodEvaluation> methods;
  /// The collection's ranking, N x N row-major, entry i*N+j = distance from
  /// model i to model j.
  std::vector<float> distances;
  RetrievalMetrics metrics;
  /// Stages summed over the methods (through the services: ingest and
  /// extraction, the build, distances and metrics).
  StageTimings timings;
  double fuse_seconds = 0;
  double rerank_seconds = 0;
};

// The collection's all-pairs ranking from its methods' matrices (each N x N,
// in the collection's order, one per method of `options`): the one matrix as
// it is when the collection is not rescaled; otherwise each divided by its
// scale (fusion.h; written to `scales`), fused with the weights, and
// re-ranked over the neighbour graph of the fused distances when the options
// say so. `seconds` (optional) receives the fusion and re-ranking times.
absl::StatusOr<std::vector<float>> CombineMethodDistances(
    const std::vector<absl::Span<const float>>& matrices,
    std::size_t n,
    const CollectionOptions& options,
    std::vector<double>* scales,
    double* fuse_seconds = nullptr,
    double* rerank_seconds = nullptr);

// Evaluates every method and combines them, then the metrics.
absl::StatusOr<CollectionEvaluation> EvaluateCollection(const std::vector<ManifestEntry>& models,
                                                        const CollectionOptions& options);

// Writes DIR/distances.bin (PSB float32 matrix, manifest order),
// DIR/models.csv (the models as a manifest, id,class,path, in matrix order
// with absolute paths: what `meshseek report` reads), for a
// collection of several methods each one's own as DIR/distances.METHOD.bin
// (when evaluated in process), and DIR/metrics.json (every metric, micro and macro, per class, the
// parameters, feature counts, each method's scale and the stage timings). Creates DIR.
absl::Status WriteEvaluation(const CollectionEvaluation& evaluation,
                             const CollectionOptions& options,
                             const std::string& out_dir);

// The document WriteEvaluation writes as metrics.json (and `meshseek eval
// --format json` prints).
Json EvaluationMetricsJson(const CollectionEvaluation& evaluation, const CollectionOptions& options);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_PIPELINE_COLLECTION_EVALUATION_H_
