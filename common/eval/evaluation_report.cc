#include "common/eval/evaluation_report.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <set>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/base/file_io.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/eval/distance_matrix.h"
#include "common/geometry/mesh_io.h"

namespace meshseek {
namespace {

// metrics.json is a few kilobytes; anything far larger is not one.
constexpr uint64_t kMaxMetricsJsonBytes = uint64_t{64} << 20;

absl::Status RequireFile(const std::string& path, absl::string_view what) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) return absl::OkStatus();
  return absl::NotFoundError(absl::StrCat(path, ": not found (", what, ")"));
}

// A metrics.json value that must agree with the recomputed one.
absl::Status CheckAgainstJson(const FlatJson& json,
                              const std::string& json_path,
                              const std::string& key,
                              double recomputed) {
  const std::optional<std::string> text = FindFlatJson(json, key);
  if (!text.has_value()) {
    return absl::InvalidArgumentError(absl::StrCat(json_path, ": no '", key, "'"));
  }
  double stored = 0;
  if (!absl::SimpleAtod(*text, &stored)) {
    return absl::InvalidArgumentError(
        absl::StrCat(json_path, ": '", key, "' is '", *text, "', not a number"));
  }
  // Written with round-trip precision, so only summation order could differ.
  if (std::abs(stored - recomputed) > 1e-9 * std::max(1.0, std::abs(stored))) {
    return absl::FailedPreconditionError(absl::StrFormat(
        "%s says %s = %.10g, but distances.bin with the labels of models.csv gives %.10g: the "
        "files are not from the same `meshseek eval` run",
        json_path,
        key,
        stored,
        recomputed));
  }
  return absl::OkStatus();
}

// Model `q`'s `top` nearest models, best first (retrieval_metrics.h).
std::vector<std::size_t> TopResults(const std::vector<float>& distances,
                                    std::size_t n,
                                    std::size_t q,
                                    std::size_t top) {
  std::vector<std::size_t> results;
  for (const auto& [distance, j] : RankOthers(distances, n, q, top)) results.push_back(j);
  return results;
}

}  // namespace

absl::Status EvaluationReportOptions::Validate() const {
  if (sample_queries < 0 || sample_queries > 100) {
    return absl::InvalidArgumentError(
        absl::StrCat("sample_queries must be in [0, 100], got ", sample_queries));
  }
  if (top_results < 1 || top_results > 50) {
    return absl::InvalidArgumentError(
        absl::StrCat("top_results must be in [1, 50], got ", top_results));
  }
  MESHSEEK_RETURN_IF_ERROR(precision_recall.Validate());
  return thumbnail.Validate();
}

absl::StatusOr<EvaluationRun> ReadEvaluationRun(const std::string& dir) {
  EvaluationRun run;
  run.dir = dir;
  const std::string models_path = dir + "/models.csv";
  const std::string matrix_path = dir + "/distances.bin";
  const std::string json_path = dir + "/metrics.json";
  MESHSEEK_RETURN_IF_ERROR(
      RequireFile(models_path, "`meshseek eval` writes it beside distances.bin; rerun eval"));
  MESHSEEK_RETURN_IF_ERROR(RequireFile(matrix_path, "is DIR a `meshseek eval --out` folder?"));
  MESHSEEK_RETURN_IF_ERROR(RequireFile(json_path, "is DIR a `meshseek eval --out` folder?"));

  MESHSEEK_ASSIGN_OR_RETURN(run.models, ReadManifest(models_path));
  absl::StatusOr<std::vector<float>> matrix = ReadDistanceMatrix(matrix_path, run.models.size());
  if (!matrix.ok()) {
    return absl::Status(matrix.status().code(),
                        absl::StrCat(matrix.status().message(),
                                     " (",
                                     models_path,
                                     " lists ",
                                     run.models.size(),
                                     " models)"));
  }
  run.distances = *std::move(matrix);

  MESHSEEK_ASSIGN_OR_RETURN(const std::string json,
                            ReadFileToString(json_path, kMaxMetricsJsonBytes));
  MESHSEEK_ASSIGN_OR_RETURN(run.metrics_json, FlattenJson(json, json_path));
  const std::optional<std::string> models = FindFlatJson(run.metrics_json, "models");
  if (models.has_value() && *models != absl::StrCat(run.models.size())) {
    return absl::InvalidArgumentError(absl::StrCat(
        json_path, " counts ", *models, " models but ", models_path, " lists ", run.models.size()));
  }
  return run;
}

absl::StatusOr<EvaluationReport> ComputeEvaluationReport(const EvaluationRun& run,
                                                         const EvaluationReportOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  const std::size_t n = run.models.size();
  EvaluationReport report;
  report.run = &run;
  report.thumbnail_size = options.thumbnail.size;
  std::vector<std::string> labels;
  for (const ManifestEntry& m : run.models) {
    labels.push_back(m.label);
    ++report.class_sizes[m.label];
  }
  MESHSEEK_ASSIGN_OR_RETURN(report.metrics,
                            EvaluateRetrieval(labels, run.distances, options.num_threads));
  PrecisionRecallOptions pr = options.precision_recall;
  pr.num_threads = options.num_threads;
  MESHSEEK_ASSIGN_OR_RETURN(report.precision_recall,
                            ComputePrecisionRecall(labels, run.distances, pr));

  const std::string json_path = run.dir + "/metrics.json";
  for (const auto& [name, scores] :
       {std::pair{"micro", &report.metrics.micro}, std::pair{"macro", &report.metrics.macro}}) {
    for (const ScoreColumn& col : ScoreColumns()) {
      MESHSEEK_RETURN_IF_ERROR(CheckAgainstJson(run.metrics_json,
                                                json_path,
                                                absl::StrCat(name, ".", col.key),
                                                100.0 * (scores->*col.field)));
    }
  }
  MESHSEEK_RETURN_IF_ERROR(CheckAgainstJson(
      run.metrics_json, json_path, "queries", static_cast<double>(report.metrics.queries)));

  // One query per class, classes spread evenly over per_class's order.
  const std::size_t classes = report.metrics.per_class.size();
  const std::size_t shown = std::min<std::size_t>(options.sample_queries, classes);
  for (std::size_t i = 0; i < shown; ++i) {
    const std::string& name = report.metrics.per_class[i * classes / shown].first;
    std::vector<std::pair<double, std::size_t>> members;  // (FT, model)
    for (const QueryScores& q : report.metrics.per_query) {
      if (labels[q.model] == name) members.emplace_back(q.scores.first_tier, q.model);
    }
    std::sort(members.begin(), members.end());
    const auto& [ft, query] = members[(members.size() - 1) / 2];
    report.samples.push_back({query, ft, TopResults(run.distances, n, query, options.top_results)});
  }

  std::set<std::size_t> pictured;
  for (const ReportSample& s : report.samples) {
    pictured.insert(s.query);
    pictured.insert(s.results.begin(), s.results.end());
  }
  const std::vector<std::size_t> models(pictured.begin(), pictured.end());
  std::vector<ReportThumbnail> thumbnails(models.size());
  ParallelFor(models.size(), options.num_threads, [&](std::size_t i) {
    absl::StatusOr<TriangleMesh> mesh = ReadMesh(run.models[models[i]].path);
    absl::StatusOr<std::string> png =
        mesh.ok() ? RenderThumbnailPng(*mesh, options.thumbnail) : mesh.status();
    if (png.ok()) {
      thumbnails[i].png = *std::move(png);
    } else {
      thumbnails[i].error = std::string(png.status().message());
    }
  });
  for (std::size_t i = 0; i < models.size(); ++i) {
    report.thumbnails[models[i]] = std::move(thumbnails[i]);
  }
  return report;
}

}  // namespace meshseek
