#include "common/eval/report_html.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/base/base64.h"
#include "common/base/status_macros.h"
#include "common/eval/svg_plot.h"

namespace meshseek {
namespace {

// One stylesheet for the page. Sizes in pixels: the report is read on a
// screen, and the thumbnails are pixel images anyway.
constexpr char kStyle[] = R"css(
*{box-sizing:border-box}
body{margin:0;background:#f3f4f6;color:#1f2328;
 font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",Arial,sans-serif}
main{max-width:1220px;margin:0 auto;padding:22px 24px 40px}
header h1{margin:0;font-size:24px;font-weight:650;letter-spacing:-.01em}
header .sub{margin:4px 0 0;color:#57606a}
code{font:12.5px ui-monospace,"DejaVu Sans Mono",monospace;background:#eef0f3;padding:1px 4px;
 border-radius:3px}
section{background:#fff;border:1px solid #d8dee4;border-radius:8px;padding:14px 18px 16px;
 margin-top:16px}
h2{margin:0 0 10px;font-size:16px;font-weight:650}
.note{color:#57606a;font-size:12.5px;margin:8px 0 0}
.row{display:flex;gap:16px;align-items:flex-start;flex-wrap:wrap}
.row>section{flex:1 1 420px;margin-top:16px}
table{border-collapse:collapse}
th,td{padding:4px 10px;text-align:right;white-space:nowrap}
th{font-weight:600;color:#57606a;font-size:12.5px;border-bottom:1px solid #d8dee4}
td:first-child,th:first-child{text-align:left}
table.metrics{font-size:16px;font-variant-numeric:tabular-nums}
table.metrics td{padding:6px 14px}
table.metrics tr.micro td{font-weight:650}
table.metrics th[title]{cursor:help}
table.classes{width:100%;font-variant-numeric:tabular-nums}
table.classes td{padding:3px 8px}
table.classes tr.avg td{border-top:1px solid #d8dee4;color:#57606a}
.bar{position:relative;width:100%;min-width:160px;height:16px;background:#eef0f3;border-radius:3px}
.bar span{position:absolute;left:0;top:0;bottom:0;background:#4e79a7;border-radius:3px}
.bar i{position:absolute;top:-3px;bottom:-3px;width:2px;background:#1f2328;opacity:.55}
td.barcell{width:45%}
.charts{display:flex;flex-wrap:wrap;gap:6px 10px}
.query{display:flex;gap:8px;align-items:flex-start;padding:10px 0;border-top:1px solid #eaeef2}
.query:first-of-type{border-top:0}
.arrow{align-self:center;color:#8c959f;font-size:22px;padding:0 2px}
figure.tile{margin:0;padding:3px;border:3px solid #d0d7de;border-radius:6px;background:#f6f8fa;
 font-size:11.5px;line-height:1.3}
figure.tile img,figure.tile .noimg{display:block;border-radius:3px}
figure.tile .noimg{display:flex;align-items:center;justify-content:center;text-align:center;
 background:repeating-linear-gradient(45deg,#eef0f3 0 6px,#e4e7eb 6px 12px);color:#57606a}
figcaption{padding:3px 2px 0;overflow:hidden;text-overflow:ellipsis;white-space:nowrap}
figcaption .cls{color:#57606a}
figure.q{border-color:#3466c2;background:#eef3fc}
figure.hit{border-color:#2e9e4f}
figure.miss{border-color:#d64541}
figure.miss .cls{color:#b3261e;font-weight:600}
.key span{display:inline-block;width:11px;height:11px;border:3px solid;border-radius:3px;
 vertical-align:-1px;margin:0 4px 0 12px}
dl.params{columns:3 260px;column-gap:28px;margin:0;font-size:12.5px}
dl.params div{break-inside:avoid;display:flex;justify-content:space-between;gap:12px;
 border-bottom:1px dotted #d8dee4;padding:2px 0}
dl.params dt{color:#57606a}
dl.params dd{margin:0;font-family:ui-monospace,"DejaVu Sans Mono",monospace;text-align:right;
 overflow-wrap:anywhere}
footer{color:#6e7781;font-size:12px;margin-top:18px}
)css";

// Distinct, readable on white (Tableau 10 without its light grey).
constexpr const char* kPalette[] = {"#4e79a7",
                                    "#f28e2b",
                                    "#e15759",
                                    "#59a14f",
                                    "#b07aa1",
                                    "#76b7b2",
                                    "#edc948",
                                    "#9c755f",
                                    "#ff9da7",
                                    "#5f6b7a"};
constexpr char kMicroColour[] = "#1f2328";

// The columns of the metrics table, as `meshseek eval` prints them, with the
// definitions of retrieval_metrics.h as tooltips.
constexpr struct {
  const char* key;
  const char* title;
  double RetrievalScores::*field;
} kColumns[] = {
    {"NN", "nearest neighbour: the rank-1 result is of the query's class", &RetrievalScores::nn},
    {"FT", "first tier: hits in the top C-1, / (C-1)", &RetrievalScores::first_tier},
    {"ST", "second tier: hits in the top 2(C-1), / (C-1)", &RetrievalScores::second_tier},
    {"E", "E-measure: F1 of precision and recall over the top 32", &RetrievalScores::e_measure},
    {"DCG", "discounted cumulative gain, normalised by the ideal ranking", &RetrievalScores::dcg},
    {"RP_excl", "R-precision, query excluded (= FT)", &RetrievalScores::rp_excl},
    {"RP_incl",
     "R-precision counting the query as its own first result: (1 + hits in the top C-1) / C",
     &RetrievalScores::rp_incl},
};

std::string Percent(double fraction) { return absl::StrFormat("%.1f", 100.0 * fraction); }

std::string Value(const FlatJson& json, absl::string_view key, absl::string_view otherwise) {
  const std::optional<std::string> v = FindFlatJson(json, key);
  return v.has_value() ? *v : std::string(otherwise);
}

// The deepest folder holding every mesh: where the data set lives.
std::string CommonFolder(const std::vector<ManifestEntry>& models) {
  if (models.empty()) return "";
  std::filesystem::path common = std::filesystem::path(models[0].path).parent_path();
  for (const ManifestEntry& m : models) {
    const std::filesystem::path folder = std::filesystem::path(m.path).parent_path();
    while (!common.empty() && !absl::StartsWith(folder.string() + "/", common.string() + "/")) {
      common = common.parent_path();
    }
  }
  return common.string();
}

std::string MetricsSection(const RetrievalMetrics& metrics) {
  std::string html = "<section><h2>Retrieval metrics <small class=note>(percent)</small></h2>";
  html += "<table class=metrics><tr><th></th>";
  for (const auto& col : kColumns) {
    absl::StrAppend(&html, "<th title=\"", EscapeXml(col.title), "\">", col.key, "</th>");
  }
  html += "</tr>";
  for (const auto& [name, scores, what] :
       {std::tuple{"micro", &metrics.micro, "mean over queries"},
        std::tuple{"macro", &metrics.macro, "mean over classes"}}) {
    absl::StrAppend(&html, "<tr class=", name, "><td title=\"", what, "\">", name, "</td>");
    for (const auto& col : kColumns) {
      absl::StrAppend(&html, "<td>", Percent(scores->*col.field), "</td>");
    }
    html += "</tr>";
  }
  absl::StrAppend(&html,
                  "</table><p class=note>",
                  metrics.queries,
                  " queries in ",
                  metrics.classes,
                  " classes, each ranking the other models by ascending distance (ties by "
                  "index). NN nearest neighbour, FT/ST first/second tier, E F1 over the top 32, "
                  "DCG normalised discounted cumulative gain, RP R-precision with the query "
                  "excluded or counted as its own first result. Micro: mean over queries; "
                  "macro: mean over classes.</p></section>");
  return html;
}

std::string ClassSection(const EvaluationReport& report) {
  std::vector<const std::pair<std::string, RetrievalScores>*> classes;
  for (const auto& c : report.metrics.per_class) classes.push_back(&c);
  std::stable_sort(classes.begin(), classes.end(), [](const auto* a, const auto* b) {
    return a->second.first_tier > b->second.first_tier;
  });
  const double micro_ft = report.metrics.micro.first_tier;
  std::string html =
      "<section><h2>First tier per class</h2><table class=classes><tr><th>class</th>"
      "<th>models</th><th>first tier (%)</th><th></th><th>NN</th><th>DCG</th></tr>";
  for (const auto* c : classes) {
    const RetrievalScores& s = c->second;
    absl::StrAppendFormat(&html,
                          "<tr><td>%s</td><td>%d</td><td class=barcell><div class=bar><span "
                          "style=\"width:%.1f%%\"></span><i style=\"left:%.1f%%\"></i></div></td>"
                          "<td>%s</td><td>%s</td><td>%s</td></tr>",
                          EscapeXml(c->first),
                          report.class_sizes.at(c->first),
                          100 * s.first_tier,
                          100 * micro_ft,
                          Percent(s.first_tier),
                          Percent(s.nn),
                          Percent(s.dcg));
  }
  for (const auto& [name, scores] : {std::pair{"all queries (micro)", &report.metrics.micro},
                                     std::pair{"mean of classes (macro)", &report.metrics.macro}}) {
    absl::StrAppend(&html,
                    "<tr class=avg><td colspan=3>",
                    name,
                    "</td><td>",
                    Percent(scores->first_tier),
                    "</td><td>",
                    Percent(scores->nn),
                    "</td><td>",
                    Percent(scores->dcg),
                    "</td></tr>");
  }
  html +=
      "</table><p class=note>Sorted by first tier; the dark tick marks the micro mean. NN and "
      "DCG in percent.</p></section>";
  return html;
}

SvgSeries Curve(const std::vector<double>& recall,
                const std::vector<double>& precision,
                const std::string& colour,
                double width,
                bool dashed,
                const std::string& label) {
  SvgSeries s;
  s.x = recall;
  s.y = precision;
  s.colour = colour;
  s.line_width = width;
  s.dashed = dashed;
  s.label = label;
  return s;
}

absl::StatusOr<std::string> PrecisionRecallSection(const EvaluationReport& report) {
  const PrecisionRecallCurves& pr = report.precision_recall;
  SvgChartOptions big;
  big.width = 500;
  big.height = 340;
  big.x_label = "recall";
  big.y_label = "precision";
  std::vector<SvgSeries> series = {
      Curve(pr.recall, pr.micro, kMicroColour, 2.5, false, "micro (mean over queries)"),
      Curve(pr.recall, pr.macro, "#e15759", 2, true, "macro (mean over classes)")};
  series[0].markers = true;
  MESHSEEK_ASSIGN_OR_RETURN(const std::string main_chart, SvgLineChart(series, big));
  std::string html = absl::StrCat(
      "<section><h2>Precision-recall</h2>",
      main_chart,
      "<p class=note>Interpolated precision (the best precision at any rank reaching the "
      "recall) at recall 0, ",
      absl::StrFormat("%g", pr.recall.size() > 1 ? pr.recall[1] : 1.0),
      ", ..., 1 for each query, averaged.</p></section>");
  return html;
}

absl::StatusOr<std::string> PerClassCurvesSection(const EvaluationReport& report) {
  const PrecisionRecallCurves& pr = report.precision_recall;
  std::string html = "<section><h2>Precision-recall per class</h2><div class=charts>";
  SvgChartOptions small;
  small.width = 214;
  small.height = 168;
  small.font_size = 10;
  small.x_ticks = 4;
  small.y_ticks = 4;
  small.legend = false;
  for (std::size_t c = 0; c < pr.per_class.size(); ++c) {
    const auto& [name, curve] = pr.per_class[c];
    small.title = absl::StrCat(name, " (", report.class_sizes.at(name), ")");
    const std::vector<SvgSeries> series = {
        Curve(pr.recall, pr.micro, "#8c959f", 1.2, true, "micro"),
        Curve(pr.recall, curve, kPalette[c % std::size(kPalette)], 2.2, false, name)};
    MESHSEEK_ASSIGN_OR_RETURN(const std::string chart, SvgLineChart(series, small));
    html += chart;
  }
  html +=
      "</div><p class=note>Each class's queries averaged (models in brackets); the dashed grey "
      "curve is the micro average over all queries. Recall across, precision up.</p></section>";
  return html;
}

std::string Tile(const EvaluationReport& report,
                 std::size_t model,
                 const std::string& css_class,
                 const std::string& top_line) {
  const ManifestEntry& m = report.run->models[model];
  const int size = report.thumbnail_size;
  std::string html = absl::StrCat("<figure class=\"tile ",
                                  css_class,
                                  "\" style=\"width:",
                                  size + 12,
                                  "px\" title=\"",
                                  EscapeXml(m.path),
                                  "\">");
  const auto it = report.thumbnails.find(model);
  if (it != report.thumbnails.end() && !it->second.png.empty()) {
    absl::StrAppend(&html,
                    "<img width=",
                    size,
                    " height=",
                    size,
                    " alt=\"",
                    EscapeXml(m.id),
                    "\" src=\"data:image/png;base64,",
                    Base64Encode(it->second.png),
                    "\">");
  } else {
    const std::string why = it == report.thumbnails.end() ? "not rendered" : it->second.error;
    absl::StrAppendFormat(&html,
                          "<div class=noimg style=\"width:%dpx;height:%dpx\" title=\"%s\">no "
                          "preview</div>",
                          size,
                          size,
                          EscapeXml(why));
  }
  absl::StrAppend(&html,
                  "<figcaption>",
                  top_line,
                  "<br>",
                  EscapeXml(m.id),
                  "<br><span class=cls>",
                  EscapeXml(m.label),
                  "</span></figcaption></figure>");
  return html;
}

std::string SamplesSection(const EvaluationReport& report) {
  if (report.samples.empty()) return "";
  const EvaluationRun& run = *report.run;
  const std::size_t n = run.models.size();
  std::string html = absl::StrCat(
      "<section><h2>Sample queries and their top ",
      report.samples.front().results.size(),
      " results</h2><p class=note style=\"margin:0 0 4px\">One query per class, the one "
      "with its class's median first tier. Border: <span class=key><span "
      "style=\"border-color:#3466c2\"></span>query<span style=\"border-color:#2e9e4f\"></span>"
      "same class (hit)<span style=\"border-color:#d64541\"></span>other class (miss)</span>. "
      "d = distance.</p>");
  for (const ReportSample& s : report.samples) {
    html += "<div class=query>";
    html += Tile(report, s.query, "q", absl::StrCat("<b>query</b> · FT ", Percent(s.first_tier)));
    html += "<div class=arrow>&#8594;</div>";
    for (std::size_t r = 0; r < s.results.size(); ++r) {
      const std::size_t j = s.results[r];
      const bool hit = run.models[j].label == run.models[s.query].label;
      html += Tile(report,
                   j,
                   hit ? "hit" : "miss",
                   absl::StrFormat("<b>%d</b> · d %.4g", r + 1, run.distances[s.query * n + j]));
    }
    html += "</div>";
  }
  html += "</section>";
  return html;
}

std::string ParametersSection(const FlatJson& json) {
  std::string params, other;
  for (const auto& [key, value] : json) {
    std::string shown = value;
    double seconds = 0;
    if (absl::StartsWith(key, "parameters.")) {
      absl::StrAppend(&params,
                      "<div><dt>",
                      EscapeXml(key.substr(11)),
                      "</dt><dd>",
                      EscapeXml(shown),
                      "</dd></div>");
    } else if (absl::StartsWith(key, "local_features.") ||
               absl::StartsWith(key, "distance_scales.") ||
               absl::StartsWith(key, "timings_seconds.")) {
      if (absl::StartsWith(key, "timings_seconds.") && absl::SimpleAtod(value, &seconds)) {
        shown = absl::StrFormat("%.1f s", seconds);
      }
      absl::StrAppend(
          &other, "<div><dt>", EscapeXml(key), "</dt><dd>", EscapeXml(shown), "</dd></div>");
    }
  }
  return absl::StrCat("<section><h2>Parameters</h2><dl class=params>",
                      params,
                      "</dl><h2 style=\"margin-top:14px\">Features and timings</h2>"
                      "<dl class=params>",
                      other,
                      "</dl></section>");
}

}  // namespace

absl::StatusOr<std::string> EvaluationReportHtml(const EvaluationReport& report) {
  const EvaluationRun& run = *report.run;
  const std::string method = Value(run.metrics_json, "parameters.method", "unknown method");
  const std::string dir = std::filesystem::path(run.dir).lexically_normal().string();
  std::size_t not_queried = run.models.size() - report.metrics.queries;
  std::string html = absl::StrCat(
      "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8>"
      "<meta name=viewport content=\"width=device-width,initial-scale=1\">"
      "<title>meshseek report: ",
      EscapeXml(method),
      " on ",
      EscapeXml(dir),
      "</title><style>",
      kStyle,
      "</style></head><body><main><header><h1>Retrieval evaluation: ",
      EscapeXml(method),
      "</h1><p class=sub>",
      run.models.size(),
      " models in ",
      report.class_sizes.size(),
      " classes, ",
      report.metrics.queries,
      " queries (leave-one-out)",
      not_queried > 0 ? absl::StrCat("; ",
                                     not_queried,
                                     " models of misc or 1-2 model classes "
                                     "are ranked but not queries")
                      : "",
      ". Run <code>",
      EscapeXml(dir),
      "</code>, meshes under <code>",
      EscapeXml(CommonFolder(run.models)),
      "</code>.</p></header>");
  html += MetricsSection(report.metrics);
  MESHSEEK_ASSIGN_OR_RETURN(const std::string pr, PrecisionRecallSection(report));
  absl::StrAppend(&html, "<div class=row>", ClassSection(report), pr, "</div>");
  MESHSEEK_ASSIGN_OR_RETURN(const std::string per_class, PerClassCurvesSection(report));
  html += per_class;
  html += SamplesSection(report);
  html += ParametersSection(run.metrics_json);
  absl::StrAppend(&html,
                  "<footer>Written by <code>meshseek report</code> from ",
                  "<code>models.csv</code>, <code>distances.bin</code> and "
                  "<code>metrics.json</code>; the metrics are recomputed from the distances "
                  "and agree with metrics.json. Protocol: meshseek docs/design.md section 3.</footer>"
                  "</main></body></html>\n");
  return html;
}

}  // namespace meshseek
