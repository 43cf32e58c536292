#include "common/search/histogram_embedding.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace meshseek {
namespace {

using ::testing::HasSubstr;

// Histograms that mix `prototypes` fixed distributions over `vocabulary`
// words: their square roots do not lie in a subspace, but nearly so, and the
// principal axes of a few dimensions then keep Hellinger distances.
std::vector<SparseHistogram> Mixtures(std::size_t count,
                                      uint32_t vocabulary,
                                      std::size_t prototypes,
                                      uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::vector<double>> proto(prototypes, std::vector<double>(vocabulary, 0.0));
  for (auto& p : proto) {
    for (uint32_t k = 0; k < vocabulary; ++k) p[k] = rng() % 4 == 0 ? 1.0 + rng() % 7 : 0.0;
  }
  std::vector<SparseHistogram> out;
  for (std::size_t i = 0; i < count; ++i) {
    std::vector<double> h(vocabulary, 0.0);
    const std::size_t a = rng() % prototypes;
    for (uint32_t k = 0; k < vocabulary; ++k) h[k] = proto[a][k];
    double sum = 0;
    for (double v : h) sum += v;
    SparseHistogram s;
    s.vocabulary = vocabulary;
    for (uint32_t k = 0; k < vocabulary; ++k) {
      if (h[k] > 0) {
        s.words.push_back(k);
        s.weights.push_back(static_cast<float>(h[k] / sum));
      }
    }
    out.push_back(s);
  }
  return out;
}

double Hellinger(const SparseHistogram& x, const SparseHistogram& y) {
  std::vector<double> dx(x.vocabulary, 0.0), dy(y.vocabulary, 0.0);
  for (std::size_t t = 0; t < x.words.size(); ++t) dx[x.words[t]] = std::sqrt(x.weights[t]);
  for (std::size_t t = 0; t < y.words.size(); ++t) dy[y.words[t]] = std::sqrt(y.weights[t]);
  double d = 0;
  for (std::size_t k = 0; k < dx.size(); ++k) d += (dx[k] - dy[k]) * (dx[k] - dy[k]);
  return std::sqrt(d);
}

std::vector<float> Embedded(const HistogramEmbedding& e, const SparseHistogram& h) {
  std::vector<float> out(e.dimensions());
  e.Embed(h.words, h.weights, out.data());
  return out;
}

double Distance(const std::vector<float>& a, const std::vector<float>& b) {
  double d = 0;
  for (std::size_t j = 0; j < a.size(); ++j) d += (double(a[j]) - b[j]) * (double(a[j]) - b[j]);
  return std::sqrt(d);
}

// Histograms drawn from 6 prototypes span (with the mean) at most 6
// dimensions of square roots: 8 axes keep every Hellinger distance.
TEST(HistogramEmbeddingTest, KeepsHellingerDistancesOfALowRankCollection) {
  const auto sample = Mixtures(300, 400, 6, 1);
  const auto embedding = HistogramEmbedding::Fit(sample, 400, 8, 7);
  ASSERT_TRUE(embedding.ok()) << embedding.status();
  EXPECT_EQ(embedding->dimensions(), 8);
  for (std::size_t i = 0; i < 20; ++i) {
    for (std::size_t j = 0; j < 20; ++j) {
      EXPECT_NEAR(Distance(Embedded(*embedding, sample[i]), Embedded(*embedding, sample[j])),
                  Hellinger(sample[i], sample[j]),
                  1e-4);
    }
  }
}

TEST(HistogramEmbeddingTest, SameSampleAndSeedGiveTheSameAxes) {
  const auto sample = Mixtures(200, 300, 20, 2);
  const auto a = HistogramEmbedding::Fit(sample, 300, 16, 3);
  const auto b = HistogramEmbedding::Fit(sample, 300, 16, 3);
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t i = 0; i < 10; ++i) {
    EXPECT_EQ(Embedded(*a, sample[i]), Embedded(*b, sample[i]));
  }
}

// Fewer histograms than dimensions: the missing axes are zero, the others
// still keep distances.
TEST(HistogramEmbeddingTest, TinySamplesLeaveUnusedAxesZero) {
  const auto sample = Mixtures(5, 50, 5, 4);
  const auto e = HistogramEmbedding::Fit(sample, 50, 32, 5);
  ASSERT_TRUE(e.ok()) << e.status();
  EXPECT_NEAR(Distance(Embedded(*e, sample[0]), Embedded(*e, sample[1])),
              Hellinger(sample[0], sample[1]),
              1e-4);
  const auto empty = HistogramEmbedding::Fit({}, 50, 4, 5);
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(Embedded(*empty, sample[0]), std::vector<float>(4, 0.0f));
}

TEST(HistogramEmbeddingTest, RejectsBadArguments) {
  const auto sample = Mixtures(3, 50, 2, 6);
  EXPECT_THAT(HistogramEmbedding::Fit(sample, 50, 0, 1).status().message(),
              HasSubstr("dimensions must be in [1, 1024], got 0"));
  EXPECT_THAT(HistogramEmbedding::Fit(sample, 60, 4, 1).status().message(),
              HasSubstr("sample histogram 0 has 50 words, expected 60"));
}

}  // namespace
}  // namespace meshseek
