// Line charts as inline SVG, for the evaluation report's precision-recall
// curves: text that any browser draws, needs no plotting library or script,
// and stays sharp when zoomed or printed. Only what the report needs: linear
// axes with a grid, labelled ticks, polylines and an optional legend.
#ifndef MESHSEEK_COMMON_EVAL_SVG_PLOT_H_
#define MESHSEEK_COMMON_EVAL_SVG_PLOT_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

// `text` with &, <, >, " and ' replaced by entities: safe inside XML/HTML
// text and quoted attributes (model ids and class names come from files).
std::string EscapeXml(absl::string_view text);

struct SvgSeries {
  std::vector<double> x;  // data coordinates, finite, as many as y
  std::vector<double> y;
  std::string colour = "#1f4e99";  // any CSS colour
  double line_width = 2;           // in pixels, > 0
  bool dashed = false;
  bool markers = false;  // a dot at every point
  std::string label;     // its legend entry; empty: not in the legend
};

struct SvgChartOptions {
  /// Size in pixels, each in [60, 4000].
  int width = 360;
  int height = 280;
  /// Axis ranges in data units (min < max); points outside are drawn on the
  /// nearest edge.
  double x_min = 0, x_max = 1;
  double y_min = 0, y_max = 1;
  /// Grid intervals per axis, each in [1, 50]; ticks are labelled at every
  /// interval, or every other one when the chart is small.
  int x_ticks = 5;
  int y_ticks = 5;
  /// Axis titles and the chart's title (empty: none).
  std::string x_label;
  std::string y_label;
  std::string title;
  /// Font size of tick labels in pixels (titles are a little larger), [6, 40].
  int font_size = 12;
  /// Draw a legend of the labelled series in the lower left corner, where
  /// falling curves such as precision-recall leave room.
  bool legend = true;

  absl::Status Validate() const;
};

// The chart as one <svg> element (width and height attributes and a viewBox,
// so CSS may scale it). InvalidArgument for invalid options or a series whose
// x and y differ in length or hold a non-finite value (naming the series).
absl::StatusOr<std::string> SvgLineChart(const std::vector<SvgSeries>& series,
                                         const SvgChartOptions& options);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_SVG_PLOT_H_
