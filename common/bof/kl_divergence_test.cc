#include "common/bof/kl_divergence.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

// Normalised histograms with about `zero_fraction` of the bins empty.
std::vector<std::vector<float>> RandomHistograms(std::size_t count,
                                                 std::size_t bins,
                                                 double zero_fraction,
                                                 uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<std::vector<float>> histograms(count, std::vector<float>(bins));
  for (auto& h : histograms) {
    std::vector<double> raw(bins);
    double sum = 0.0;
    for (double& v : raw) sum += v = uniform(rng) < zero_fraction ? 0.0 : uniform(rng);
    for (std::size_t k = 0; k < bins; ++k) h[k] = static_cast<float>(raw[k] / sum);
  }
  return histograms;
}

double Divergence(const std::vector<float>& x,
                  const std::vector<float>& y,
                  const KlDivergenceOptions& options = {}) {
  const absl::StatusOr<double> d = SymmetricKlDivergence(x, y, options);
  EXPECT_TRUE(d.ok()) << d.status();
  return d.value_or(-1.0);
}

TEST(KlDivergenceOptionsTest, DefaultsAreValidAndPinned) {
  const KlDivergenceOptions options;
  EXPECT_TRUE(options.Validate().ok());
  EXPECT_EQ(options.epsilon, 1e-10);
  EXPECT_EQ(options.sum_tolerance, 1e-3);
}

TEST(KlDivergenceOptionsTest, RejectsBadValuesNamingThem) {
  KlDivergenceOptions options;
  for (double bad : {0.0, -1e-6, 1.0, std::nan("")}) {
    options.epsilon = bad;
    EXPECT_THAT(std::string(options.Validate().message()),
                HasSubstr(absl::StrCat("epsilon must be in (0, 1), got ", bad)));
  }
  options = KlDivergenceOptions();
  options.sum_tolerance = -0.1;
  EXPECT_THAT(std::string(options.Validate().message()),
              HasSubstr("sum_tolerance must be in [0, 1), got -0.1"));
}

TEST(SymmetricKlDivergenceTest, KnownValueByHand) {
  // D = 0.3 ln(0.5/0.2) + 0 + (-0.3) ln(0.2/0.5) = 0.6 ln 2.5. A tiny epsilon
  // keeps the smoothing below the tolerance.
  KlDivergenceOptions options;
  options.epsilon = 1e-12;
  EXPECT_NEAR(
      Divergence({0.5f, 0.3f, 0.2f}, {0.2f, 0.3f, 0.5f}, options), 0.6 * std::log(2.5), 1e-7);
}

TEST(SymmetricKlDivergenceTest, EpsilonRuleOnZeroBinsByHand) {
  // x = (1, 0), y = (0, 1), eps = 0.1: x' = (11/12, 1/12), y' = (1/12, 11/12),
  // D = 2 * (10/12) ln 11.
  KlDivergenceOptions options;
  options.epsilon = 0.1;
  EXPECT_NEAR(Divergence({1, 0}, {0, 1}, options), 20.0 / 12.0 * std::log(11.0), 1e-12);
  // Disjoint supports stay finite under the default epsilon, too.
  const double d = Divergence({0.5f, 0.5f, 0, 0}, {0, 0, 0.5f, 0.5f});
  EXPECT_TRUE(std::isfinite(d));
  EXPECT_GT(d, 10.0);
}

TEST(SymmetricKlDivergenceTest, IsZeroOnItselfSymmetricAndNonNegative) {
  const auto histograms = RandomHistograms(20, 300, 0.3, 1);
  for (std::size_t i = 0; i < histograms.size(); ++i) {
    EXPECT_EQ(Divergence(histograms[i], histograms[i]), 0.0);
    for (std::size_t j = 0; j < i; ++j) {
      const double d = Divergence(histograms[i], histograms[j]);
      EXPECT_GT(d, 0.0);
      EXPECT_EQ(d, Divergence(histograms[j], histograms[i]));  // exactly
    }
  }
}

TEST(SymmetricKlDivergenceTest, InvariantToBinPermutation) {
  auto histograms = RandomHistograms(2, 1000, 0.5, 2);
  const double before = Divergence(histograms[0], histograms[1]);
  std::vector<std::size_t> order(1000);
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  std::vector<std::vector<float>> permuted(2, std::vector<float>(1000));
  for (int h = 0; h < 2; ++h) {
    for (std::size_t k = 0; k < 1000; ++k) permuted[h][k] = histograms[h][order[k]];
  }
  EXPECT_NEAR(Divergence(permuted[0], permuted[1]), before, 1e-12 * before);
}

TEST(SymmetricKlDistanceMatrixTest, EqualsThePairwisePathExactly) {
  const auto histograms = RandomHistograms(37, 203, 0.4, 4);  // > 2 row blocks
  const absl::StatusOr<std::vector<float>> matrix =
      SymmetricKlDistanceMatrix(histograms, {}, /*num_threads=*/2);
  ASSERT_TRUE(matrix.ok()) << matrix.status();
  const std::size_t n = histograms.size();
  ASSERT_EQ(matrix->size(), n * n);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ((*matrix)[i * n + i], 0.0f);
    for (std::size_t j = 0; j < n; ++j) {
      EXPECT_EQ((*matrix)[i * n + j], (*matrix)[j * n + i]);
      if (i != j) {
        EXPECT_EQ((*matrix)[i * n + j],
                  static_cast<float>(Divergence(histograms[i], histograms[j])))
            << i << ", " << j;
      }
    }
  }
  EXPECT_EQ(*matrix, SymmetricKlDistanceMatrix(histograms, {}, 1).value());
}

TEST(SymmetricKlDistancesTest, QueryPathEqualsTheMatrixRow) {
  const auto histograms = RandomHistograms(150, 64, 0.2, 5);  // > 2 query tasks
  const std::vector<float> matrix = SymmetricKlDistanceMatrix(histograms, {}, 1).value();
  const std::size_t n = histograms.size();
  for (std::size_t q : {0u, 77u, 149u}) {
    const absl::StatusOr<std::vector<float>> row =
        SymmetricKlDistances(histograms[q], histograms, {}, 2);
    ASSERT_TRUE(row.ok()) << row.status();
    EXPECT_EQ(*row, std::vector<float>(matrix.begin() + q * n, matrix.begin() + (q + 1) * n));
  }
  const absl::StatusOr<KlHistogramSet> set = KlHistogramSet::Create(histograms);
  ASSERT_TRUE(set.ok());
  EXPECT_EQ(set->size(), n);
  EXPECT_EQ(set->bins(), 64u);
  EXPECT_THAT(std::string(set->DistancesFrom({1.0f}, 1).status().message()),
              HasSubstr("query has 1 bins, expected 64"));
}

TEST(SymmetricKlDivergenceTest, ValidatesHistogramsWithTheValues) {
  auto message = [](const std::vector<float>& x, const std::vector<float>& y) {
    const absl::StatusOr<double> d = SymmetricKlDivergence(x, y);
    EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(d.status().message());
  };
  EXPECT_THAT(message({0.5f, 0.5f}, {1.0f}), HasSubstr("histogram 1 has 1 bins, expected 2"));
  EXPECT_THAT(message({}, {}), HasSubstr("histogram 0 has 0 bins"));
  EXPECT_THAT(message({1.5f, -0.5f}, {0.5f, 0.5f}),
              HasSubstr("histogram 0, bin 1 is -0.5 (must be finite and >= 0)"));
  EXPECT_THAT(message({0.5f, 0.5f}, {std::nanf(""), 1.0f}), HasSubstr("histogram 1, bin 0 is nan"));
  EXPECT_THAT(message({0.5f, 0.5f}, {3.0f, 5.0f}),
              HasSubstr("histogram 1 sums to 8, expected 1 within 0.001"));
  EXPECT_THAT(std::string(SymmetricKlDistanceMatrix({}, {}, 1).status().message()),
              HasSubstr("no histograms"));
  KlDivergenceOptions bad;
  bad.epsilon = 0;
  EXPECT_THAT(std::string(SymmetricKlDistanceMatrix({{1.0f}}, bad, 1).status().message()),
              HasSubstr("epsilon"));
}

}  // namespace
}  // namespace meshseek
