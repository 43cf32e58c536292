#include "common/eval/precision_recall.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace meshseek {
namespace {

using ::testing::DoubleNear;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(PrecisionRecallOptionsTest, DefaultsAreValidAndBadStepsAreRejected) {
  EXPECT_TRUE(PrecisionRecallOptions().Validate().ok());
  PrecisionRecallOptions options;
  options.recall_steps = 0;
  EXPECT_THAT(std::string(options.Validate().message()), HasSubstr("got 0"));
}

TEST(InterpolatedPrecisionTest, HandComputedRankings) {
  // Hits at ranks 1, 3 and 6 (k = 3): precision 1, 2/3 and 1/2 at recall
  // 1/3, 2/3 and 1.
  const std::vector<bool> ranking = {true, false, true, false, false, true};
  EXPECT_THAT(InterpolatedPrecision(ranking, 3), ElementsAre(1.0, 1.0, 2.0 / 3, 0.5));
  // At recall 0.25 the first hit (recall 1/3) is the first rank far enough;
  // 0.75 needs all three hits.
  EXPECT_THAT(InterpolatedPrecision(ranking, 4), ElementsAre(1.0, 1.0, 2.0 / 3, 0.5, 0.5));
  // Interpolation lifts precision 1/2 at the first hit to the 2/3 reached
  // later, so the curve never rises.
  EXPECT_THAT(InterpolatedPrecision({false, true, true}, 2),
              ElementsAre(2.0 / 3, 2.0 / 3, 2.0 / 3));
}

// Five models, classes A A A B B: B has 2 models, so only 0, 1 and 2 are
// queries, each with k = 2 relevant models.
//   query 0 ranks 1 3 4 2: hits at ranks 1 and 4 -> precision 1, 1/2
//   query 1 ranks 3 4 0 2: hits at ranks 3 and 4 -> 1/3, 1/2 -> interpolated 1/2, 1/2
//   query 2 ranks 0 3 1 4: 0 and 3 tie at distance 1, the lower index first:
//                          hits at ranks 1 and 3 -> 1, 2/3
TEST(ComputePrecisionRecallTest, HandComputedTinyExample) {
  const std::vector<std::string> labels = {"A", "A", "A", "B", "B"};
  // clang-format off
  const std::vector<float> distances = {
      0, 1, 4, 2, 3,
      3, 0, 4, 1, 2,
      1, 2, 0, 1, 3,
      1, 1, 1, 0, 1,
      1, 1, 1, 1, 0};
  // clang-format on
  PrecisionRecallOptions options;
  options.recall_steps = 2;  // levels 0, 0.5, 1
  auto curves = ComputePrecisionRecall(labels, distances, options);
  ASSERT_TRUE(curves.ok()) << curves.status();
  EXPECT_EQ(curves->queries, 3u);
  EXPECT_THAT(curves->recall, ElementsAre(0.0, 0.5, 1.0));
  // Means of (1, 1/2, 1) and (1/2, 1/2, 2/3).
  const double low = 5.0 / 6, high = 5.0 / 9;
  EXPECT_THAT(curves->micro,
              ElementsAre(DoubleNear(low, 1e-12), DoubleNear(low, 1e-12), DoubleNear(high, 1e-12)));
  ASSERT_EQ(curves->per_class.size(), 1u);
  EXPECT_EQ(curves->per_class[0].first, "A");
  EXPECT_EQ(curves->macro, curves->micro);

  // The usual 21 levels: up to 0.5 one hit suffices, from 0.55 both are needed.
  auto fine = ComputePrecisionRecall(labels, distances);
  ASSERT_TRUE(fine.ok()) << fine.status();
  ASSERT_EQ(fine->recall.size(), 21u);
  EXPECT_DOUBLE_EQ(fine->recall[11], 0.55);
  EXPECT_NEAR(fine->micro[10], low, 1e-12);
  EXPECT_NEAR(fine->micro[11], high, 1e-12);
  EXPECT_NEAR(fine->micro[20], high, 1e-12);
}

TEST(ComputePrecisionRecallTest, MacroAveragesClassesAndMiscIsNeverAQuery) {
  // Classes of 3 and 5, a pair and two misc models; random distances.
  const std::vector<std::string> labels = {
      "a", "a", "a", "b", "b", "b", "b", "b", "p", "p", "-1", "-1"};
  const std::size_t n = labels.size();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<float> distances(n * n);
  for (float& d : distances) d = uniform(rng);
  distances[2 * n + 5] = std::numeric_limits<float>::infinity();  // ranked last
  PrecisionRecallOptions options;
  options.num_threads = 3;
  auto curves = ComputePrecisionRecall(labels, distances, options);
  ASSERT_TRUE(curves.ok()) << curves.status();
  EXPECT_EQ(curves->queries, 8u);
  ASSERT_EQ(curves->per_class.size(), 2u);
  EXPECT_EQ(curves->per_class[0].first, "a");
  EXPECT_EQ(curves->per_class[1].first, "b");
  for (std::size_t s = 0; s < curves->recall.size(); ++s) {
    const double a = curves->per_class[0].second[s], b = curves->per_class[1].second[s];
    EXPECT_NEAR(curves->macro[s], (a + b) / 2, 1e-12);
    EXPECT_NEAR(curves->micro[s], (3 * a + 5 * b) / 8, 1e-12);
    if (s > 0) {
      EXPECT_LE(curves->micro[s], curves->micro[s - 1]);
    }
    EXPECT_GT(curves->micro[s], 0);
    EXPECT_LE(curves->micro[s], 1);
  }
  // The thread count does not change anything.
  options.num_threads = 1;
  auto serial = ComputePrecisionRecall(labels, distances, options);
  ASSERT_TRUE(serial.ok());
  EXPECT_EQ(serial->micro, curves->micro);
}

TEST(ComputePrecisionRecallTest, RejectsBadInput) {
  EXPECT_FALSE(ComputePrecisionRecall({}, {}).ok());
  EXPECT_THAT(std::string(ComputePrecisionRecall({"a", "a", "a"}, {0, 1}).status().message()),
              HasSubstr("got 2 distances for 3 labels"));
  std::vector<float> nan(9, 1.0f);
  nan[5] = std::nanf("");
  EXPECT_THAT(std::string(ComputePrecisionRecall({"a", "a", "a"}, nan).status().message()),
              HasSubstr("row 1, column 2"));
  EXPECT_THAT(
      std::string(
          ComputePrecisionRecall({"a", "a", "-1"}, std::vector<float>(9)).status().message()),
      HasSubstr("no model can be a query"));
  PrecisionRecallOptions options;
  options.recall_steps = 5000;
  EXPECT_FALSE(ComputePrecisionRecall({"a", "a", "a"}, std::vector<float>(9), options).ok());
}

}  // namespace
}  // namespace meshseek
