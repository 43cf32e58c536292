#include "common/eval/svg_plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace meshseek {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

TEST(EscapeXmlTest, EscapesMarkupCharacters) {
  EXPECT_EQ(EscapeXml("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;");
  EXPECT_EQ(EscapeXml("plain"), "plain");
}

TEST(SvgChartOptionsTest, DefaultsAreValidAndBadValuesNamed) {
  EXPECT_TRUE(SvgChartOptions().Validate().ok());
  SvgChartOptions options;
  options.x_max = options.x_min;
  EXPECT_THAT(std::string(options.Validate().message()), HasSubstr("min < max"));
  options = SvgChartOptions();
  options.width = 10;
  EXPECT_THAT(std::string(options.Validate().message()), HasSubstr("got 10 x 280"));
  options = SvgChartOptions();
  options.y_ticks = 0;
  EXPECT_FALSE(options.Validate().ok());
}

TEST(SvgLineChartTest, MapsDataToThePlotAreaAndLabelsIt) {
  SvgChartOptions options;
  options.width = 200;
  options.height = 120;
  options.font_size = 10;
  options.x_ticks = 2;
  options.y_ticks = 2;
  options.title = "PR <micro>";
  SvgSeries line;
  line.x = {0, 0.5, 1};
  line.y = {1, 0.5, 2};  // 2 is beyond the range: drawn on the top edge
  line.colour = "#c00";
  line.label = "class \"a\"";
  auto svg = SvgLineChart({line}, options);
  ASSERT_TRUE(svg.ok()) << svg.status();
  EXPECT_THAT(*svg, StartsWith("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\""));
  EXPECT_THAT(*svg, HasSubstr("</svg>"));
  // Margins for f = 10 with a title and no axis labels: left 26, right 9,
  // top 21, bottom 17, so the plot is x in [26, 191], y in [21, 103].
  EXPECT_THAT(*svg, HasSubstr("points=\"26.0,21.0 108.5,62.0 191.0,21.0\""));
  EXPECT_THAT(*svg, HasSubstr("stroke=\"#c00\""));
  EXPECT_THAT(*svg, HasSubstr(">PR &lt;micro&gt;</text>"));
  EXPECT_THAT(*svg, HasSubstr(">class &quot;a&quot;</text>"));  // the legend
  EXPECT_THAT(*svg, HasSubstr(">0.5</text>"));                  // a tick label

  options.legend = false;
  auto bare = SvgLineChart({line}, options);
  ASSERT_TRUE(bare.ok());
  EXPECT_THAT(*bare, Not(HasSubstr("class &quot;a&quot;")));
}

TEST(SvgLineChartTest, RefusesMalformedSeries) {
  SvgSeries bad;
  bad.x = {0, 1};
  bad.y = {0};
  bad.label = "micro";
  EXPECT_THAT(std::string(SvgLineChart({bad}, {}).status().message()),
              HasSubstr("micro has 2 x values and 1 y values"));
  bad.y = {0, std::nan("")};
  EXPECT_THAT(std::string(SvgLineChart({bad}, {}).status().message()),
              HasSubstr("point 1 is not finite"));
}

}  // namespace
}  // namespace meshseek
