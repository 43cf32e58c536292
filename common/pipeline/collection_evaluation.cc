#include "common/pipeline/collection_evaluation.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <numeric>

#include "absl/strings/str_cat.h"
#include "common/base/file_io.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/eval/distance_matrix.h"
#include "common/search/fusion.h"
#include "common/search/neighbor_graph.h"
#include "common/search/rerank.h"

namespace meshseek {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Json FeatureCounts(const MethodEvaluation& method) {
  Json counts = Json::MakeObject();
  if (method.features_per_model.empty()) return counts;
  std::vector<std::size_t> sorted = method.features_per_model;
  std::sort(sorted.begin(), sorted.end());
  counts.Set("total",
             static_cast<int64_t>(std::accumulate(sorted.begin(), sorted.end(), std::size_t{0})));
  counts.Set("min_per_model", static_cast<int64_t>(sorted.front()));
  counts.Set("median_per_model", static_cast<int64_t>(sorted[sorted.size() / 2]));
  counts.Set("max_per_model", static_cast<int64_t>(sorted.back()));
  counts.Set("models_without_features", static_cast<int64_t>(method.models_without_features));
  return counts;
}

Json Timings(const StageTimings& t) {
  Json timings = Json::MakeObject();
  timings.Set("extract", t.extract_seconds);
  timings.Set("codebook", t.codebook_seconds);
  timings.Set("encode", t.encode_seconds);
  timings.Set("rank", t.rank_seconds);
  timings.Set("total", t.total_seconds);
  return timings;
}

}  // namespace

absl::StatusOr<std::vector<float>> CombineMethodDistances(
    const std::vector<absl::Span<const float>>& matrices,
    std::size_t n,
    const CollectionOptions& options,
    std::vector<double>* scales,
    double* fuse_seconds,
    double* rerank_seconds) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  if (matrices.size() != options.methods.size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        matrices.size(), " distance matrices for ", options.methods.size(), " methods"));
  }
  for (const absl::Span<const float>& m : matrices) {
    if (m.size() != n * n) {
      return absl::InvalidArgumentError(
          absl::StrCat("a distance matrix of ", m.size(), " entries for ", n, " models"));
    }
  }
  scales->assign(matrices.size(), 1.0);
  if (!options.rescaled()) return std::vector<float>(matrices[0].begin(), matrices[0].end());

  auto start = std::chrono::steady_clock::now();
  for (std::size_t m = 0; m < matrices.size(); ++m) {
    DistanceScale scale;
    for (std::size_t r : ScaleSampleRows(n)) scale.AddRow(r, matrices[m].subspan(r * n, n));
    (*scales)[m] = scale.Scale();
  }
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<double> factors,
                            FusionFactors(options.weights, *scales));
  std::vector<float> fused(n * n);
  const int threads = options.num_threads();
  ParallelFor(n, threads, [&](std::size_t i) {
    std::vector<absl::Span<const float>> rows;
    for (const absl::Span<const float>& m : matrices) rows.push_back(m.subspan(i * n, n));
    FuseRows(rows, factors, absl::MakeSpan(fused).subspan(i * n, n));
  });
  if (fuse_seconds != nullptr) *fuse_seconds = SecondsSince(start);
  if (!options.rerank.enabled()) return fused;

  start = std::chrono::steady_clock::now();
  MESHSEEK_ASSIGN_OR_RETURN(const NeighborGraph graph,
                            NeighborGraph::FromMatrix(fused, n, options.rerank.graph_k(), threads));
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<float> ranked,
                            RerankMatrix(graph, fused, options.rerank, threads));
  if (rerank_seconds != nullptr) *rerank_seconds = SecondsSince(start);
  return ranked;
}

absl::StatusOr<CollectionEvaluation> EvaluateCollection(const std::vector<ManifestEntry>& models,
                                                        const CollectionOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  if (models.empty()) return absl::InvalidArgumentError("the collection has no models");
  const auto start = std::chrono::steady_clock::now();
  CollectionEvaluation result;
  result.models = models;
  for (const RetrievalPipelineOptions& method : options.methods) {
    MESHSEEK_ASSIGN_OR_RETURN(MethodEvaluation evaluated, EvaluateMethod(models, method));
    result.timings.extract_seconds += evaluated.timings.extract_seconds;
    result.timings.codebook_seconds += evaluated.timings.codebook_seconds;
    result.timings.encode_seconds += evaluated.timings.encode_seconds;
    result.timings.rank_seconds += evaluated.timings.rank_seconds;
    result.methods.push_back(std::move(evaluated));
  }
  std::vector<absl::Span<const float>> matrices;
  for (const MethodEvaluation& m : result.methods) matrices.push_back(m.distances);
  std::vector<double> scales;
  MESHSEEK_ASSIGN_OR_RETURN(
      result.distances,
      CombineMethodDistances(
          matrices, models.size(), options, &scales, &result.fuse_seconds, &result.rerank_seconds));
  for (std::size_t m = 0; m < scales.size(); ++m) result.methods[m].scale = scales[m];

  std::vector<std::string> labels;
  labels.reserve(models.size());
  for (const ManifestEntry& m : models) labels.push_back(m.label);
  MESHSEEK_ASSIGN_OR_RETURN(result.metrics,
                            EvaluateRetrieval(labels, result.distances, options.num_threads()));
  result.timings.total_seconds = SecondsSince(start);
  return result;
}

absl::Status WriteEvaluation(const CollectionEvaluation& evaluation,
                             const CollectionOptions& options,
                             const std::string& out_dir) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    return absl::PermissionDeniedError(
        absl::StrCat(out_dir, ": cannot create folder (", ec.message(), ")"));
  }
  MESHSEEK_RETURN_IF_ERROR(WriteDistanceMatrix(
      out_dir + "/distances.bin", evaluation.distances, evaluation.models.size()));
  // The models in matrix order with absolute paths, so that `meshseek report`
  // can label the rows and find the meshes from any working folder.
  std::vector<ManifestEntry> models = evaluation.models;
  for (ManifestEntry& m : models) {
    m.path = std::filesystem::absolute(m.path, ec).lexically_normal().string();
    if (ec) {
      return absl::InvalidArgumentError(
          absl::StrCat(m.path, ": cannot make the path absolute (", ec.message(), ")"));
    }
  }
  MESHSEEK_RETURN_IF_ERROR(WriteManifest(out_dir + "/models.csv", models));
  if (evaluation.methods.size() > 1) {
    // Each method's own matrix beside the fused one: the ablation's input
    // (bench/fusion_sweep) without extracting again.
    for (const MethodEvaluation& m : evaluation.methods) {
      if (m.distances.empty()) continue;
      MESHSEEK_RETURN_IF_ERROR(WriteDistanceMatrix(
          absl::StrCat(out_dir, "/distances.", FeatureMethodName(m.method), ".bin"),
          m.distances,
          evaluation.models.size()));
    }
  }
  return WriteStringToFile(out_dir + "/metrics.json", EvaluationMetricsJson(evaluation, options).Dump());
}

Json EvaluationMetricsJson(const CollectionEvaluation& evaluation, const CollectionOptions& options) {
  Json report = MetricsToJson(evaluation.metrics);
  report.Set("models", static_cast<int64_t>(evaluation.models.size()));
  report.Set("parameters", options.ToJson());
  if (evaluation.methods.size() == 1) {
    report.Set("local_features", FeatureCounts(evaluation.methods.front()));
  } else {
    Json& counts = report.Set("local_features", Json::MakeObject());
    for (const MethodEvaluation& m : evaluation.methods) {
      counts.Set(FeatureMethodName(m.method), FeatureCounts(m));
    }
  }
  if (options.rescaled()) {
    Json& scales = report.Set("distance_scales", Json::MakeObject());
    for (const MethodEvaluation& m : evaluation.methods) {
      scales.Set(FeatureMethodName(m.method), m.scale);
    }
  }
  Json timings = Timings(evaluation.timings);
  if (options.rescaled()) {
    timings.Set("fuse", evaluation.fuse_seconds);
    timings.Set("rerank", evaluation.rerank_seconds);
  }
  if (evaluation.methods.size() > 1) {
    for (const MethodEvaluation& m : evaluation.methods) {
      timings.Set(FeatureMethodName(m.method), Timings(m.timings));
    }
  }
  report.Set("timings_seconds", std::move(timings));
  return report;
}

}  // namespace meshseek
