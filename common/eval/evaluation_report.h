// The evaluation report: what `meshseek eval` left in its folder, turned into
// the figures a person reads (docs/design.md 3): the metrics, first tier per class,
// precision-recall curves, and a few queries' top results as pictures.
//
// Reading (ReadEvaluationRun) and computing (ComputeEvaluationReport) are
// here; report_html.h lays the result out as one HTML page. The metrics are
// recomputed from distances.bin and the labels of models.csv with the same
// code eval used, and checked against metrics.json, so the report cannot show
// numbers that differ from what eval printed or mix files of different runs.
#ifndef MESHSEEK_COMMON_EVAL_EVALUATION_REPORT_H_
#define MESHSEEK_COMMON_EVAL_EVALUATION_REPORT_H_

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/eval/flat_json.h"
#include "common/eval/manifest.h"
#include "common/eval/precision_recall.h"
#include "common/eval/retrieval_metrics.h"
#include "common/render/thumbnail.h"

namespace meshseek {

// The files of one `meshseek eval --out DIR`.
struct EvaluationRun {
  std::string dir;
  /// DIR/models.csv: the models in matrix order (id, class, mesh path).
  std::vector<ManifestEntry> models;
  /// DIR/distances.bin: N x N, row-major, N = models.size().
  std::vector<float> distances;
  /// DIR/metrics.json, flattened (flat_json.h): the metrics eval printed,
  /// the parameters, feature counts and timings.
  FlatJson metrics_json;
};

// Reads DIR/models.csv, DIR/distances.bin and DIR/metrics.json.
// Errors name the file: NotFound when one is missing (models.csv is written
// by eval since the report exists: rerun eval); InvalidArgument when
// models.csv is malformed, distances.bin is not N x N float32 for the N
// models of models.csv or holds NaN, metrics.json is malformed or counts a
// different number of models.
absl::StatusOr<EvaluationRun> ReadEvaluationRun(const std::string& dir);

struct EvaluationReportOptions {
  /// Queries shown with their top results: one per class (the one whose
  /// first tier is the class's median, so a typical one), classes spread
  /// evenly when there are more. In [0, 100].
  int sample_queries = 12;
  /// Results shown per sampled query, in [1, 50].
  int top_results = 8;
  /// The precision-recall curves' sampling.
  PrecisionRecallOptions precision_recall;
  /// The pictures of the sampled queries and their results.
  ThumbnailOptions thumbnail = DefaultThumbnail();
  /// Threads for the metrics and the thumbnails (<= 0: all cores).
  int num_threads = 0;

  static ThumbnailOptions DefaultThumbnail() {
    ThumbnailOptions t;
    t.size = 104;  // 8 results and the query fit a 1200-pixel page
    return t;
  }
  absl::Status Validate() const;
};

// A thumbnail of one model, or why there is none.
struct ReportThumbnail {
  std::string png;    // PNG bytes; empty when the mesh could not be drawn
  std::string error;  // why not (the reader's or renderer's message)
};

struct ReportSample {
  std::size_t query = 0;             // model index
  double first_tier = 0;             // the query's own FT, a fraction
  std::vector<std::size_t> results;  // top results, best first (model indices)
};

struct EvaluationReport {
  const EvaluationRun* run = nullptr;  // not owned
  RetrievalMetrics metrics;
  PrecisionRecallCurves precision_recall;
  /// Models per class (every class, misc included), by name.
  std::map<std::string, std::size_t> class_sizes;
  std::vector<ReportSample> samples;
  /// Thumbnails of every sampled query and result, by model index, each
  /// thumbnail_size pixels square.
  std::map<std::size_t, ReportThumbnail> thumbnails;
  int thumbnail_size = 0;
};

// Computes the report of `run` (which must outlive it). A mesh that cannot
// be read or drawn gets a thumbnail with only an error, not a failure.
// Errors: InvalidArgument for invalid options or labels with no query;
// FailedPrecondition when the recomputed micro or macro metrics differ from
// metrics.json's (naming the metric and both values: the files are from
// different runs or were edited).
absl::StatusOr<EvaluationReport> ComputeEvaluationReport(const EvaluationRun& run,
                                                         const EvaluationReportOptions& options);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_EVALUATION_REPORT_H_
