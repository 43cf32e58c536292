// meshseek report: the HTML report of an eval folder (evaluation_report.h,
// report_html.h).
#include <cstdio>
#include <string>

#include "absl/flags/declare.h"
#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "cli/commands.h"
#include "common/base/file_io.h"
#include "common/base/status_macros.h"
#include "common/eval/evaluation_report.h"
#include "common/eval/report_html.h"

ABSL_FLAG(std::string, eval, "", "report: folder written by `meshseek eval --out`");
ABSL_FLAG(int,
          sample_queries,
          meshseek::EvaluationReportOptions().sample_queries,
          "report: queries shown with their top results (one per class)");
ABSL_FLAG(int,
          top_results,
          meshseek::EvaluationReportOptions().top_results,
          "report: results shown per sampled query");
ABSL_FLAG(int,
          thumbnail_size,
          meshseek::EvaluationReportOptions().thumbnail.size,
          "report: thumbnail size in pixels");
ABSL_DECLARE_FLAG(std::string, out);
ABSL_DECLARE_FLAG(int, threads);

namespace meshseek::cli {

absl::Status RunReport() {
  const std::string eval_dir = absl::GetFlag(FLAGS_eval);
  std::string out = absl::GetFlag(FLAGS_out);
  if (eval_dir.empty()) return absl::InvalidArgumentError("report needs --eval DIR");
  if (out.empty()) out = eval_dir + "/report.html";

  EvaluationReportOptions options;
  options.sample_queries = absl::GetFlag(FLAGS_sample_queries);
  options.top_results = absl::GetFlag(FLAGS_top_results);
  options.thumbnail.size = absl::GetFlag(FLAGS_thumbnail_size);
  options.num_threads = absl::GetFlag(FLAGS_threads);
  if (absl::Status valid = options.Validate(); !valid.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("flags: ", valid.message()));
  }
  MESHSEEK_ASSIGN_OR_RETURN(const EvaluationRun run, ReadEvaluationRun(eval_dir));
  MESHSEEK_ASSIGN_OR_RETURN(const EvaluationReport report, ComputeEvaluationReport(run, options));
  MESHSEEK_ASSIGN_OR_RETURN(const std::string html, EvaluationReportHtml(report));
  MESHSEEK_RETURN_IF_ERROR(WriteStringToFile(out, html));

  std::size_t missing = 0;
  for (const auto& [model, thumbnail] : report.thumbnails) {
    if (!thumbnail.png.empty()) continue;
    if (++missing <= 3) {
      std::fprintf(stderr,
                   "meshseek report: no picture of model '%s': %s\n",
                   run.models[model].id.c_str(),
                   thumbnail.error.c_str());
    }
  }
  std::printf("%s", FormatMetricsTable(report.metrics).c_str());
  std::printf("wrote %s (%zu KB: %zu sample queries, %zu thumbnails%s)\n",
              out.c_str(),
              html.size() / 1024,
              report.samples.size(),
              report.thumbnails.size(),
              missing > 0 ? absl::StrCat(", ", missing, " without a picture").c_str() : "");
  return absl::OkStatus();
}

}  // namespace meshseek::cli
