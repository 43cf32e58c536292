#include "common/eval/svg_plot.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace meshseek {
namespace {

constexpr char kTextColour[] = "#444";
constexpr char kAxisColour[] = "#999";
constexpr char kGridColour[] = "#e6e6e6";

}  // namespace

std::string EscapeXml(absl::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out.push_back(c);
    }
  }
  return out;
}

absl::Status SvgChartOptions::Validate() const {
  if (width < 60 || width > 4000 || height < 60 || height > 4000) {
    return absl::InvalidArgumentError(
        absl::StrCat("chart size must be in [60, 4000] pixels, got ", width, " x ", height));
  }
  if (!(x_min < x_max) || !(y_min < y_max) || !std::isfinite(x_max - x_min) ||
      !std::isfinite(y_max - y_min)) {
    return absl::InvalidArgumentError(absl::StrCat("chart ranges need finite min < max, got x [",
                                                   x_min,
                                                   ", ",
                                                   x_max,
                                                   "], y [",
                                                   y_min,
                                                   ", ",
                                                   y_max,
                                                   "]"));
  }
  if (x_ticks < 1 || x_ticks > 50 || y_ticks < 1 || y_ticks > 50) {
    return absl::InvalidArgumentError(
        absl::StrCat("tick counts must be in [1, 50], got ", x_ticks, " and ", y_ticks));
  }
  if (font_size < 6 || font_size > 40) {
    return absl::InvalidArgumentError(
        absl::StrCat("font_size must be in [6, 40], got ", font_size));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> SvgLineChart(const std::vector<SvgSeries>& series,
                                         const SvgChartOptions& options) {
  if (absl::Status s = options.Validate(); !s.ok()) return s;
  for (std::size_t i = 0; i < series.size(); ++i) {
    const SvgSeries& s = series[i];
    const std::string name = s.label.empty() ? absl::StrCat("series ", i) : s.label;
    if (s.x.size() != s.y.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, " has ", s.x.size(), " x values and ", s.y.size(), " y values"));
    }
    for (std::size_t j = 0; j < s.x.size(); ++j) {
      if (!std::isfinite(s.x[j]) || !std::isfinite(s.y[j])) {
        return absl::InvalidArgumentError(absl::StrCat(name, ": point ", j, " is not finite"));
      }
    }
    if (!(s.line_width > 0)) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": line width must be > 0"));
    }
  }

  // Margins leave room for the tick labels and titles.
  const double f = options.font_size;
  const double left = f * 2.6 + (options.y_label.empty() ? 0 : f * 1.5);
  const double bottom = f * 1.7 + (options.x_label.empty() ? 0 : f * 1.4);
  const double top = options.title.empty() ? f * 0.8 : f * 2.1;
  const double right = f * 0.9;
  const double pw = std::max(1.0, options.width - left - right);
  const double ph = std::max(1.0, options.height - top - bottom);
  auto px = [&](double v) {
    v = std::clamp(v, options.x_min, options.x_max);
    return left + (v - options.x_min) / (options.x_max - options.x_min) * pw;
  };
  auto py = [&](double v) {
    v = std::clamp(v, options.y_min, options.y_max);
    return top + ph - (v - options.y_min) / (options.y_max - options.y_min) * ph;
  };

  std::string svg = absl::StrFormat(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
      "viewBox=\"0 0 %d %d\" role=\"img\" aria-label=\"%s\" font-size=\"%d\" fill=\"%s\">",
      options.width,
      options.height,
      options.width,
      options.height,
      EscapeXml(options.title),
      options.font_size,
      kTextColour);
  absl::StrAppendFormat(
      &svg,
      "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"#fff\"/>",
      left,
      top,
      pw,
      ph);
  // Grid and tick labels; a crowded axis labels every other tick.
  const int x_label_every = pw / options.x_ticks < f * 2.6 ? 2 : 1;
  const int y_label_every = ph / options.y_ticks < f * 1.4 ? 2 : 1;
  for (int i = 0; i <= options.x_ticks; ++i) {
    const double v = options.x_min + (options.x_max - options.x_min) * i / options.x_ticks;
    absl::StrAppendFormat(&svg,
                          "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>",
                          px(v),
                          top,
                          px(v),
                          top + ph,
                          kGridColour);
    if (i % x_label_every != 0) continue;
    absl::StrAppendFormat(&svg,
                          "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%g</text>",
                          px(v),
                          top + ph + f * 1.25,
                          v);
  }
  for (int i = 0; i <= options.y_ticks; ++i) {
    const double v = options.y_min + (options.y_max - options.y_min) * i / options.y_ticks;
    absl::StrAppendFormat(&svg,
                          "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>",
                          left,
                          py(v),
                          left + pw,
                          py(v),
                          kGridColour);
    if (i % y_label_every != 0) continue;
    absl::StrAppendFormat(&svg,
                          "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%g</text>",
                          left - f * 0.35,
                          py(v) + f * 0.35,
                          v);
  }
  absl::StrAppendFormat(&svg,
                        "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
                        "stroke=\"%s\"/>",
                        left,
                        top,
                        pw,
                        ph,
                        kAxisColour);
  if (!options.title.empty()) {
    absl::StrAppendFormat(&svg,
                          "<text x=\"%.1f\" y=\"%.1f\" font-size=\"%.1f\" font-weight=\"600\">%s"
                          "</text>",
                          left,
                          f * 1.35,
                          f * 1.15,
                          EscapeXml(options.title));
  }
  if (!options.x_label.empty()) {
    absl::StrAppendFormat(&svg,
                          "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s</text>",
                          left + pw / 2,
                          options.height - f * 0.4,
                          EscapeXml(options.x_label));
  }
  if (!options.y_label.empty()) {
    const double x = f * 1.0, y = top + ph / 2;
    absl::StrAppendFormat(
        &svg,
        "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" transform=\"rotate(-90 %.1f %.1f)\">"
        "%s</text>",
        x,
        y,
        x,
        y,
        EscapeXml(options.y_label));
  }

  for (const SvgSeries& s : series) {
    std::string points;
    for (std::size_t j = 0; j < s.x.size(); ++j) {
      absl::StrAppendFormat(&points, "%s%.1f,%.1f", j > 0 ? " " : "", px(s.x[j]), py(s.y[j]));
    }
    absl::StrAppendFormat(&svg,
                          "<polyline points=\"%s\" fill=\"none\" stroke=\"%s\" "
                          "stroke-width=\"%g\" stroke-linejoin=\"round\"%s/>",
                          points,
                          EscapeXml(s.colour),
                          s.line_width,
                          s.dashed ? " stroke-dasharray=\"5 4\"" : "");
    if (!s.markers) continue;
    for (std::size_t j = 0; j < s.x.size(); ++j) {
      absl::StrAppendFormat(&svg,
                            "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"%g\" fill=\"%s\"/>",
                            px(s.x[j]),
                            py(s.y[j]),
                            s.line_width + 1,
                            EscapeXml(s.colour));
    }
  }

  std::vector<const SvgSeries*> labelled;
  for (const SvgSeries& s : series) {
    if (!s.label.empty()) labelled.push_back(&s);
  }
  if (options.legend && !labelled.empty()) {
    // Text width is not measurable here; 0.6 em per character is a fair
    // bound for the sans-serif fonts of the report.
    std::size_t longest = 0;
    for (const SvgSeries* s : labelled) longest = std::max(longest, s->label.size());
    const double row = f * 1.4;
    const double box_w = longest * f * 0.6 + f * 3.2;
    const double box_h = row * labelled.size() + f * 0.6;
    const double x0 = left + f * 0.6, y0 = top + ph - f * 0.6 - box_h;
    absl::StrAppendFormat(&svg,
                          "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" rx=\"3\" "
                          "fill=\"#fff\" fill-opacity=\"0.9\" stroke=\"#ddd\"/>",
                          x0,
                          y0,
                          box_w,
                          box_h);
    for (std::size_t i = 0; i < labelled.size(); ++i) {
      const double y = y0 + f * 0.3 + row * (i + 0.5);
      absl::StrAppendFormat(&svg,
                            "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
                            "stroke-width=\"%g\"%s/>",
                            x0 + f * 0.5,
                            y,
                            x0 + f * 2.1,
                            y,
                            EscapeXml(labelled[i]->colour),
                            labelled[i]->line_width,
                            labelled[i]->dashed ? " stroke-dasharray=\"5 4\"" : "");
      absl::StrAppendFormat(&svg,
                            "<text x=\"%.1f\" y=\"%.1f\">%s</text>",
                            x0 + f * 2.6,
                            y + f * 0.35,
                            EscapeXml(labelled[i]->label));
    }
  }
  svg += "</svg>";
  return svg;
}

}  // namespace meshseek
