// meshseek report: the HTML report of an eval folder (evaluation_report.h,
// report_html.h).
#include <cstdio>
#include <string>

#include "absl/strings/str_cat.h"
#include "cli/commands.h"
#include "common/base/file_io.h"
#include "common/base/status_macros.h"
#include "common/eval/evaluation_report.h"
#include "common/eval/report_html.h"

namespace meshseek::cli {

absl::Status RunReport(const CliFlags& flags) {
  const std::string& eval_dir = flags.eval_dir;
  if (eval_dir.empty()) return absl::InvalidArgumentError("report needs --eval DIR");
  const std::string out = flags.out.empty() ? eval_dir + "/report.html" : flags.out;
  const EvaluationReportOptions& options = flags.report;
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
