#include "common/bof/nearest_centroid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace meshseek {
namespace {

std::vector<float> RandomFloats(std::size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  std::vector<float> values(count);
  for (float& v : values) v = uniform(rng);
  return values;
}

// Nearest centroid by the definition, in double, plus the runner-up distance.
struct BruteForce {
  uint32_t label;
  double best;
  double second;
};
BruteForce Nearest(const float* x, const std::vector<float>& centroids, std::size_t dim) {
  BruteForce result{
      0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  for (std::size_t c = 0; c < centroids.size() / dim; ++c) {
    double d2 = 0.0;
    for (std::size_t d = 0; d < dim; ++d) {
      const double e = static_cast<double>(x[d]) - centroids[c * dim + d];
      d2 += e * e;
    }
    if (d2 < result.best) {
      result.second = result.best;
      result.best = d2;
      result.label = static_cast<uint32_t>(c);
    } else if (d2 < result.second) {
      result.second = d2;
    }
  }
  return result;
}

// Sizes that are not multiples of the kernel's 4 rows, 8 lanes, 128-point
// tasks or its tile, so every remainder path runs.
TEST(NearestCentroidIndexTest, MatchesBruteForce) {
  for (std::size_t dim : {1u, 7u, 128u}) {
    const std::size_t k = 203, n = 1001;
    const std::vector<float> centroids = RandomFloats(k * dim, 1);
    const std::vector<float> points = RandomFloats(n * dim, 2);
    NearestCentroidIndex index(centroids.data(), k, dim);
    std::vector<uint32_t> labels(n);
    std::vector<float> distances(n);
    index.Search(points.data(), n, 1, labels.data(), distances.data());
    std::size_t compared = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const BruteForce expected = Nearest(&points[i * dim], centroids, dim);
      // The float expansion ||x||^2 - 2 x.c + ||c||^2 errs in proportion to the
      // norms (all coordinates are in [-1, 1]), so rounding may only decide
      // between candidates closer than that.
      const double tolerance = 1e-6 * (1.0 + 2.0 * static_cast<double>(dim));
      EXPECT_NEAR(distances[i], expected.best, tolerance) << "point " << i;
      if (expected.second - expected.best > tolerance) {
        EXPECT_EQ(labels[i], expected.label) << "dim " << dim << ", point " << i;
        ++compared;
      }
    }
    EXPECT_GT(compared, n * 4 / 5) << "dim " << dim;  // near-ties are rare
  }
}

TEST(NearestCentroidIndexTest, Uint8InputEqualsItsFloatConversion) {
  const std::size_t k = 37, n = 300, dim = 128;
  std::mt19937 rng(3);
  std::vector<uint8_t> points(n * dim);
  for (uint8_t& v : points) v = static_cast<uint8_t>(rng() % 256);
  std::vector<float> centroids(k * dim);
  for (float& v : centroids) v = static_cast<float>(rng() % 25600) / 100.0f;
  const std::vector<float> as_float(points.begin(), points.end());
  NearestCentroidIndex index(centroids.data(), k, dim);
  std::vector<uint32_t> labels_u8(n), labels_f(n);
  std::vector<float> dist_u8(n), dist_f(n);
  index.Search(points.data(), n, 1, labels_u8.data(), dist_u8.data());
  index.Search(as_float.data(), n, 1, labels_f.data(), dist_f.data());
  EXPECT_EQ(labels_u8, labels_f);
  EXPECT_EQ(dist_u8, dist_f);
}

TEST(NearestCentroidIndexTest, ThreadCountDoesNotChangeResults) {
  const std::size_t k = 150, n = 2000, dim = 64;
  const std::vector<float> centroids = RandomFloats(k * dim, 4);
  const std::vector<float> points = RandomFloats(n * dim, 5);
  NearestCentroidIndex index(centroids.data(), k, dim);
  std::vector<uint32_t> labels1(n), labels2(n);
  std::vector<float> dist1(n), dist2(n);
  index.Search(points.data(), n, 1, labels1.data(), dist1.data());
  index.Search(points.data(), n, 2, labels2.data(), dist2.data());
  EXPECT_EQ(labels1, labels2);
  EXPECT_EQ(dist1, dist2);
}

TEST(NearestCentroidIndexTest, TiesGoToTheLowestIndex) {
  // Centroids 1 and 3 are the same point; 0 and 2 are farther from the query.
  const std::vector<float> centroids = {5, 5, 1, 1, 5, 5, 1, 1};
  NearestCentroidIndex index(centroids.data(), 4, 2);
  const float point[2] = {1, 1};
  uint32_t label = 99;
  float distance = -1;
  index.Search(point, 1, 1, &label, &distance);
  EXPECT_EQ(label, 1u);
  EXPECT_EQ(distance, 0.0f);
}

TEST(NearestCentroidIndexTest, DistancesAreOptionalAndEmptyInputIsANoOp) {
  const std::vector<float> centroids = {0, 0, 10, 10};
  NearestCentroidIndex index(centroids.data(), 2, 2);
  EXPECT_EQ(index.num_centroids(), 2u);
  EXPECT_EQ(index.dim(), 2u);
  const float points[4] = {9, 9, -1, 0};
  uint32_t labels[2];
  index.Search(points, 2, 1, labels, nullptr);
  EXPECT_EQ(labels[0], 1u);
  EXPECT_EQ(labels[1], 0u);
  index.Search(points, 0, 2, labels, nullptr);
}

// k = 1 is Search(); larger k lists the k smallest scores in order (ties by
// index), each score being ||c||^2 - 2 x.c.
TEST(NearestCentroidIndexTest, SearchTopKListsTheNearestInOrder) {
  const std::size_t dim = 7, k = 203, n = 301;
  std::vector<float> centroids = RandomFloats(k * dim, 5);
  // Two duplicated centroids: their scores tie and the lower index comes first.
  std::copy_n(&centroids[10 * dim], dim, &centroids[150 * dim]);
  const std::vector<float> points = RandomFloats(n * dim, 6);
  NearestCentroidIndex index(centroids.data(), k, dim);
  std::vector<uint32_t> exact(n);
  index.Search(points.data(), n, 1, exact.data(), nullptr);
  std::vector<uint32_t> top1(n);
  std::vector<float> score1(n);
  index.SearchTopK(points.data(), n, 1, top1.data(), score1.data());
  EXPECT_EQ(top1, exact);

  const std::size_t top = 12;
  std::vector<uint32_t> labels(n * top);
  std::vector<float> scores(n * top);
  index.SearchTopK(points.data(), n, top, labels.data(), scores.data());
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(labels[i * top], exact[i]);
    EXPECT_EQ(scores[i * top], score1[i]);
    for (std::size_t j = 0; j < top; ++j) {
      const float* c = &centroids[labels[i * top + j] * dim];
      double expected = 0.0;
      for (std::size_t d = 0; d < dim; ++d) {
        expected += static_cast<double>(c[d]) * c[d] - 2.0 * points[i * dim + d] * c[d];
      }
      EXPECT_NEAR(scores[i * top + j], expected, 1e-5);
      if (j == 0) continue;
      EXPECT_LE(scores[i * top + j - 1], scores[i * top + j]);
      if (scores[i * top + j - 1] == scores[i * top + j]) {
        EXPECT_LT(labels[i * top + j - 1], labels[i * top + j]);
      }
    }
    // Nothing outside the list is nearer than its last entry.
    std::vector<bool> listed(k, false);
    for (std::size_t j = 0; j < top; ++j) listed[labels[i * top + j]] = true;
    for (std::size_t c = 0; c < k; ++c) {
      if (listed[c]) continue;
      double s = 0.0;
      for (std::size_t d = 0; d < dim; ++d) {
        s += static_cast<double>(centroids[c * dim + d]) * centroids[c * dim + d] -
             2.0 * points[i * dim + d] * centroids[c * dim + d];
      }
      EXPECT_GE(s, scores[i * top + top - 1] - 1e-5);
    }
  }
}

// Every kernel variant this CPU can run (SSE2 always; AVX2 and AVX-512 where
// present) gives the same bits: labels, distances and top-k scores, on sizes
// that leave remainders of the 8-row blocks, 16-lane panels and tiles.
TEST(NearestCentroidIndexTest, EveryKernelVariantGivesTheSameBits) {
  const std::size_t k = 2003, n = 517, dim = 128, top = 5;
  std::mt19937 rng(7);
  std::vector<uint8_t> points(n * dim);
  for (uint8_t& v : points) v = static_cast<uint8_t>(rng() % 64);
  std::vector<float> centroids = RandomFloats(k * dim, 8);
  for (float& c : centroids) c = 32.0f + 32.0f * c;
  std::vector<float> float_points(points.begin(), points.end());
  const SimdLevel levels[] = {SimdLevel::kSse2, SimdLevel::kAvx2, SimdLevel::kAvx512};
  std::vector<uint32_t> labels[3], top_labels[3];
  std::vector<float> distances[3], top_scores[3];
  for (int v = 0; v < 3; ++v) {
    const NearestCentroidIndex index(centroids.data(), k, dim, levels[v]);
    if (index.simd() != levels[v]) {
      EXPECT_LT(static_cast<int>(DetectedSimdLevel()), v) << "variant " << v << " not taken";
      labels[v] = labels[0], distances[v] = distances[0];
      top_labels[v] = top_labels[0], top_scores[v] = top_scores[0];
      continue;
    }
    labels[v].resize(n);
    distances[v].resize(n);
    index.Search(points.data(), n, 2, labels[v].data(), distances[v].data());
    top_labels[v].resize(n * top);
    top_scores[v].resize(n * top);
    index.SearchTopK(float_points.data(), n, top, top_labels[v].data(), top_scores[v].data());
    if (v == 0) continue;
    EXPECT_EQ(labels[v], labels[0]) << SimdLevelName(levels[v]);
    EXPECT_EQ(distances[v], distances[0]) << SimdLevelName(levels[v]);
    EXPECT_EQ(top_labels[v], top_labels[0]) << SimdLevelName(levels[v]);
    EXPECT_EQ(top_scores[v], top_scores[0]) << SimdLevelName(levels[v]);
  }
}

}  // namespace
}  // namespace meshseek
