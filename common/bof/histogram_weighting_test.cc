#include "common/bof/histogram_weighting.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

namespace meshseek {
namespace {

TEST(HistogramWeightingTest, DefaultsLeaveHistogramsAsTheyAre) {
  const HistogramWeighting defaults;
  EXPECT_FALSE(defaults.idf);
  EXPECT_EQ(defaults.power, 1.0);
  EXPECT_FALSE(defaults.enabled());
  std::vector<std::vector<float>> histograms = {{0.25f, 0.75f}, {}, {1.0f, 0.0f}};
  const auto before = histograms;
  ASSERT_TRUE(WeightCollection(defaults, &histograms).ok());
  EXPECT_EQ(histograms, before);
}

TEST(HistogramWeightingTest, PowerOutsideItsRangeIsRefusedByName) {
  for (double power : {0.0, -0.5, 1.5, std::nan("")}) {
    HistogramWeighting w;
    w.power = power;
    const absl::Status status = w.Validate();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << power;
    EXPECT_NE(status.message().find("power"), std::string::npos);
  }
}

TEST(HistogramWeightingTest, SquareRootDampsRepeatedWordsAndKeepsUnitMass) {
  HistogramWeighting w;
  w.power = 0.5;
  std::vector<float> h = {0.64f, 0.36f, 0.0f};
  ASSERT_TRUE(WeightHistogram(w, {}, absl::MakeSpan(h)).ok());
  // sqrt: 0.8, 0.6, renormalised by 1.4.
  EXPECT_NEAR(h[0], 0.8 / 1.4, 1e-6);
  EXPECT_NEAR(h[1], 0.6 / 1.4, 1e-6);
  EXPECT_EQ(h[2], 0.0f);
}

TEST(HistogramWeightingTest, IdfFavoursWordsFewModelsHave) {
  // Word 0 in every model, word 1 in one, word 2 in two of three.
  std::vector<std::vector<float>> histograms = {
      {0.5f, 0.5f, 0.0f}, {0.5f, 0.0f, 0.5f}, {0.5f, 0.0f, 0.5f}, {}};
  const std::vector<float> idf = InverseDocumentFrequencies(histograms);
  ASSERT_EQ(idf.size(), 3u);
  EXPECT_NEAR(idf[0], 1.0, 1e-6);  // ln(4/4) + 1: smoothed, never 0
  EXPECT_NEAR(idf[1], std::log(4.0 / 2.0) + 1, 1e-6);
  EXPECT_NEAR(idf[2], std::log(4.0 / 3.0) + 1, 1e-6);
  HistogramWeighting w;
  w.idf = true;
  ASSERT_TRUE(WeightCollection(w, &histograms).ok());
  EXPECT_GT(histograms[0][1], histograms[0][0]);
  EXPECT_TRUE(histograms[3].empty());  // a model without features stays one
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(std::accumulate(histograms[i].begin(), histograms[i].end(), 0.0), 1.0, 1e-6);
  }
}

TEST(HistogramWeightingTest, IdfOfAnotherLengthIsRefused) {
  HistogramWeighting w;
  w.idf = true;
  std::vector<float> h = {0.5f, 0.5f};
  const std::vector<float> idf = {1.0f, 1.0f, 1.0f};
  EXPECT_EQ(WeightHistogram(w, idf, absl::MakeSpan(h)).code(), absl::StatusCode::kInvalidArgument);
}

TEST(HistogramWeightingTest, EveryHistogramEmptyGivesNoIdf) {
  EXPECT_TRUE(InverseDocumentFrequencies({{}, {}}).empty());
}

}  // namespace
}  // namespace meshseek
