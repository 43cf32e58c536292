#include "common/bof/approximate_nearest_centroid.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "common/bof/nearest_centroid.h"

namespace meshseek {
namespace {

// Clustered data like a visual vocabulary: `v` centroids scattered (sigma 4)
// around 400 overlapping "super-clusters" (sigma 6), and points each drawn near
// a random centroid with noise (sigma 4) as large as the spread of centroids,
// so the nearest centroid is often not the one a point was drawn from and
// often lies in another group. (With 40 well-separated super-clusters every
// probe list covers the whole neighbourhood and agreement is 1.0000; with
// unstructured Gaussian centroids it is 0.936.)
struct Clustered {
  std::vector<float> centroids;
  std::vector<float> points;
};
Clustered MakeClustered(std::size_t v, std::size_t n, std::size_t dim, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  constexpr std::size_t kSuper = 400;
  std::vector<float> super(kSuper * dim);
  for (float& x : super) x = 6.0f * normal(rng);
  Clustered data;
  data.centroids.resize(v * dim);
  for (std::size_t c = 0; c < v; ++c) {
    const std::size_t s = rng() % kSuper;
    for (std::size_t d = 0; d < dim; ++d) {
      data.centroids[c * dim + d] = super[s * dim + d] + 4.0f * normal(rng);
    }
  }
  data.points.resize(n * dim);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = rng() % v;
    for (std::size_t d = 0; d < dim; ++d) {
      data.points[i * dim + d] = data.centroids[c * dim + d] + 4.0f * normal(rng);
    }
  }
  return data;
}

struct Result {
  std::vector<uint32_t> labels;
  std::vector<float> distances;
};
Result Exact(const Clustered& data, std::size_t v, std::size_t dim) {
  const std::size_t n = data.points.size() / dim;
  Result r{std::vector<uint32_t>(n), std::vector<float>(n)};
  NearestCentroidIndex(data.centroids.data(), v, dim)
      .Search(data.points.data(), n, 1, r.labels.data(), r.distances.data());
  return r;
}
Result Approximate(const Clustered& data,
                   std::size_t v,
                   std::size_t dim,
                   const ApproximateSearchParams& params,
                   int threads) {
  const std::size_t n = data.points.size() / dim;
  Result r{std::vector<uint32_t>(n), std::vector<float>(n)};
  ApproximateNearestCentroidIndex(data.centroids.data(), v, dim, params, threads)
      .Search(data.points.data(), n, threads, r.labels.data(), r.distances.data());
  return r;
}

TEST(ApproximateSearchParamsTest, ResolvesAutomaticGroupsAndClamps) {
  EXPECT_EQ(ApproximateSearchParams::Resolve(0, 8, 20000), (ApproximateSearchParams{400, 8}));
  EXPECT_EQ(ApproximateSearchParams::Resolve(0, 8, 2000), (ApproximateSearchParams{126, 8}));
  EXPECT_EQ(ApproximateSearchParams::Resolve(50, 4, 2000), (ApproximateSearchParams{50, 4}));
  // Never more groups than centroids, nor more probes than groups.
  EXPECT_EQ(ApproximateSearchParams::Resolve(0, 8, 3), (ApproximateSearchParams{3, 3}));
  EXPECT_EQ(ApproximateSearchParams::Resolve(10, 20, 100), (ApproximateSearchParams{10, 10}));
  EXPECT_EQ(ApproximateSearchParams::Resolve(0, 1, 1), (ApproximateSearchParams{1, 1}));
}

// Probing every group is an exact search, bit for bit (same distances, same
// tie rule), whatever the block and group remainders.
TEST(ApproximateNearestCentroidIndexTest, ProbingEveryGroupIsExact) {
  const std::size_t v = 301, dim = 13;
  Clustered data = MakeClustered(v, 5003, dim, 1);
  // A duplicated centroid, to exercise the tie rule across groups.
  std::copy_n(&data.centroids[7 * dim], dim, &data.centroids[200 * dim]);
  const Result exact = Exact(data, v, dim);
  const Result approx = Approximate(data, v, dim, ApproximateSearchParams{17, 17}, 1);
  EXPECT_EQ(approx.labels, exact.labels);
  EXPECT_EQ(approx.distances, exact.distances);
}

// On clustered data the default probes find the exact nearest centroid for
// almost every point (measured 0.9930), and the points that miss it land on a
// centroid nearly as close (objective ratio measured 1.0102).
TEST(ApproximateNearestCentroidIndexTest, AgreesWithExactOnClusteredData) {
  const std::size_t v = 2000, dim = 32, n = 8000;
  const Clustered data = MakeClustered(v, n, dim, 2);
  const Result exact = Exact(data, v, dim);
  const Result approx = Approximate(data, v, dim, ApproximateSearchParams::Resolve(0, 8, v), 1);
  std::size_t same = 0;
  double exact_sum = 0.0, approx_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    same += approx.labels[i] == exact.labels[i];
    exact_sum += exact.distances[i];
    approx_sum += approx.distances[i];
    // Never nearer than the nearest.
    EXPECT_GE(approx.distances[i], exact.distances[i]);
  }
  const double agreement = static_cast<double>(same) / n;
  std::printf("agreement %.4f, objective ratio %.5f\n", agreement, approx_sum / exact_sum);
  EXPECT_GE(agreement, 0.98);
  EXPECT_LE(approx_sum / exact_sum, 1.02);
}

TEST(ApproximateNearestCentroidIndexTest, IsIndependentOfThreadCountAndDeterministic) {
  const std::size_t v = 500, dim = 16;
  const Clustered data = MakeClustered(v, 9000, dim, 3);  // three 4,096-point blocks
  const ApproximateSearchParams params = ApproximateSearchParams::Resolve(0, 2, v);
  const Result one = Approximate(data, v, dim, params, 1);
  const Result two = Approximate(data, v, dim, params, 2);
  const Result again = Approximate(data, v, dim, params, 3);
  EXPECT_EQ(one.labels, two.labels);
  EXPECT_EQ(one.distances, two.distances);
  EXPECT_EQ(one.labels, again.labels);
}

TEST(ApproximateNearestCentroidIndexTest, Uint8PointsMatchTheirFloatValues) {
  const std::size_t v = 64, dim = 8, n = 1000;
  std::mt19937 rng(4);
  std::vector<float> centroids(v * dim);
  for (float& c : centroids) c = static_cast<float>(rng() % 256);
  std::vector<uint8_t> bytes(n * dim);
  for (uint8_t& b : bytes) b = static_cast<uint8_t>(rng() % 256);
  const std::vector<float> floats(bytes.begin(), bytes.end());
  ApproximateNearestCentroidIndex index(centroids.data(), v, dim, {8, 3}, 1);
  std::vector<uint32_t> a(n), b(n);
  index.Search(bytes.data(), n, 1, a.data(), nullptr);
  index.Search(floats.data(), n, 1, b.data(), nullptr);
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace meshseek
