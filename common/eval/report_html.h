// The evaluation report as one self-contained HTML page: inline CSS, inline
// SVG plots (svg_plot.h), thumbnails as data: URIs, no script and no external
// address, so that it can be mailed, archived next to the run or opened
// offline and still show everything.
#ifndef MESHSEEK_COMMON_EVAL_REPORT_HTML_H_
#define MESHSEEK_COMMON_EVAL_REPORT_HTML_H_

#include <string>

#include "absl/status/statusor.h"
#include "common/eval/evaluation_report.h"

namespace meshseek {

// The page of `report`: a header naming the method and the run, the metrics
// table (micro and macro, percent, one decimal: the figures `meshseek eval`
// prints), first tier per class as bars, precision-recall curves (micro and
// macro, then one small chart per class), the sampled queries' top results
// with hits and misses marked, and the run's parameters from metrics.json.
// Errors only if a plot cannot be drawn (non-finite values).
absl::StatusOr<std::string> EvaluationReportHtml(const EvaluationReport& report);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_REPORT_HTML_H_
