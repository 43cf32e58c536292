#include "common/search/sparse_histogram.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

namespace meshseek {
namespace {

using ::testing::HasSubstr;

TEST(SparseHistogramTest, DenseRoundTripDropsZeros) {
  const std::vector<float> dense = {0.0f, 0.25f, 0.0f, 0.75f};
  const SparseHistogram sparse = SparseFromDense(dense);
  EXPECT_EQ(sparse.vocabulary, 4u);
  EXPECT_THAT(sparse.words, ::testing::ElementsAre(1u, 3u));
  EXPECT_THAT(sparse.weights, ::testing::ElementsAre(0.25f, 0.75f));
  EXPECT_TRUE(sparse.Validate("h", 1e-3).ok());
  EXPECT_EQ(DenseFromSparse(sparse), dense);
}

TEST(SparseHistogramTest, EmptyIsValid) {
  SparseHistogram empty;
  empty.vocabulary = 10;
  EXPECT_TRUE(empty.Validate("h", 1e-3).ok());
  EXPECT_TRUE(empty.empty());
}

TEST(SparseHistogramTest, RejectsWhatIsNotADistribution) {
  auto error = [](SparseHistogram h) { return std::string(h.Validate("model 7", 1e-3).message()); };
  EXPECT_THAT(error({0, {}, {}}), HasSubstr("model 7 has vocabulary size 0"));
  EXPECT_THAT(error({kMaxVocabulary + 1, {}, {}}), HasSubstr("more than the limit"));
  EXPECT_THAT(error({4, {1}, {0.5f, 0.5f}}), HasSubstr("1 words but 2 weights"));
  EXPECT_THAT(error({4, {1, 4}, {0.5f, 0.5f}}), HasSubstr("word 4 is out of range or order"));
  EXPECT_THAT(error({4, {2, 1}, {0.5f, 0.5f}}), HasSubstr("previous word 2"));
  EXPECT_THAT(error({4, {1, 2}, {1.0f, 0.0f}}), HasSubstr("word 2: weight 0"));
  EXPECT_THAT(error({4, {1, 2}, {std::numeric_limits<float>::quiet_NaN(), 1.0f}}),
              HasSubstr("must be finite"));
  EXPECT_THAT(error({4, {1, 2}, {0.5f, 0.4f}}), HasSubstr("sums to 0.9"));
  EXPECT_THAT(error({2, {0, 1, 2}, {0.3f, 0.3f, 0.4f}}), HasSubstr("3 words for a vocabulary of 2"));
}

}  // namespace
}  // namespace meshseek
