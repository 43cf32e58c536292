#include "common/search/fusion.h"

#include <gtest/gtest.h>

#include <limits>

namespace meshseek {
namespace {

TEST(FusionTest, SampleRowsSpreadOverTheCollection) {
  EXPECT_EQ(ScaleSampleRows(3), (std::vector<std::size_t>{0, 1, 2}));
  const std::vector<std::size_t> rows = ScaleSampleRows(1000);
  ASSERT_EQ(rows.size(), kScaleRows);
  EXPECT_EQ(rows.front(), 0u);
  EXPECT_EQ(rows[1], 3u);  // 1000 / 256
  EXPECT_EQ(rows.back(), 996u);
  EXPECT_TRUE(ScaleSampleRows(0).empty());
}

TEST(FusionTest, ScaleIsTheMeanOfFiniteDistancesBetweenDifferentModels) {
  const float inf = std::numeric_limits<float>::infinity();
  DistanceScale scale;
  scale.AddRow(0, std::vector<float>{0, 2, 4, inf});
  scale.AddRow(1, std::vector<float>{2, 9, 6, inf});  // 9: its own entry, skipped
  EXPECT_DOUBLE_EQ(scale.Scale(), (2 + 4 + 2 + 6) / 4.0);
  EXPECT_EQ(DistanceScale().Scale(), 1.0);
}

TEST(FusionTest, FusedDistanceIsTheWeightedMeanOfScaledDistances) {
  auto factors = FusionFactors(std::vector<double>{1, 3}, std::vector<double>{2, 10});
  ASSERT_TRUE(factors.ok());
  EXPECT_DOUBLE_EQ((*factors)[0], 1.0 / (2 * 4));
  EXPECT_DOUBLE_EQ((*factors)[1], 3.0 / (10 * 4));
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> a = {0, 4, inf}, b = {0, 20, 10};
  std::vector<float> out(3);
  const std::vector<absl::Span<const float>> rows = {a, b};
  FuseRows(rows, *factors, absl::MakeSpan(out));
  EXPECT_EQ(out[0], 0.0f);
  EXPECT_FLOAT_EQ(out[1], 0.5f + 1.5f);  // both scaled to 2, weighted 1:3
  EXPECT_EQ(out[2], inf);
  // A member weighted 0 is left out, +inf and all.
  auto only_b = FusionFactors(std::vector<double>{0, 1}, std::vector<double>{2, 10});
  FuseRows(rows, *only_b, absl::MakeSpan(out));
  EXPECT_FLOAT_EQ(out[2], 1.0f);
}

TEST(FusionTest, BadWeightsAndScalesAreNamed) {
  EXPECT_FALSE(FusionFactors(std::vector<double>{1}, std::vector<double>{1, 1}).ok());
  EXPECT_NE(FusionFactors(std::vector<double>{1, -1}, std::vector<double>{1, 1})
                .status()
                .message()
                .find("weight 2 is -1"),
            std::string::npos);
  EXPECT_FALSE(FusionFactors(std::vector<double>{0, 0}, std::vector<double>{1, 1}).ok());
  EXPECT_FALSE(FusionFactors(std::vector<double>{1}, std::vector<double>{0}).ok());
}

}  // namespace
}  // namespace meshseek
