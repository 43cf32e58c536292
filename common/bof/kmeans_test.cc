#include "common/bof/kmeans.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

// `clusters` Gaussian blobs (sigma 1) in `dim` dimensions with centres drawn
// uniformly in [-100, 100]^dim, `per_cluster` points each, interleaved.
struct Blobs {
  std::vector<float> centres;
  std::vector<float> points;
};
Blobs MakeBlobs(std::size_t clusters, std::size_t per_cluster, std::size_t dim, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(-100.0f, 100.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Blobs blobs;
  blobs.centres.resize(clusters * dim);
  for (float& v : blobs.centres) v = uniform(rng);
  for (std::size_t i = 0; i < per_cluster; ++i) {
    for (std::size_t c = 0; c < clusters; ++c) {
      for (std::size_t d = 0; d < dim; ++d) {
        blobs.points.push_back(blobs.centres[c * dim + d] + normal(rng));
      }
    }
  }
  return blobs;
}

double Distance(const float* a, const float* b, std::size_t dim) {
  double d2 = 0.0;
  for (std::size_t d = 0; d < dim; ++d) d2 += (a[d] - b[d]) * (a[d] - b[d]);
  return std::sqrt(d2);
}

KMeansOptions SmallOptions(int k) {
  KMeansOptions options;
  options.num_centroids = k;
  options.min_points_per_centroid = 1;  // small test sets: no warnings
  return options;
}

TEST(KMeansOptionsTest, DefaultsAreValidAndPinned) {
  const KMeansOptions options;
  EXPECT_TRUE(options.Validate().ok());
  EXPECT_EQ(options.num_centroids, 1000);
  EXPECT_EQ(options.max_iterations, 25);
  EXPECT_EQ(options.tolerance, 1e-4);
  EXPECT_EQ(options.seed, 0u);
  EXPECT_EQ(options.num_threads, 0);
  EXPECT_EQ(options.max_points_per_centroid, 256);
  EXPECT_EQ(options.min_points_per_centroid, 39);
  EXPECT_EQ(options.init_points_per_centroid, 8);
  EXPECT_EQ(options.assignment, KMeansOptions::Assignment::kAuto);
  EXPECT_EQ(options.approximate_min_centroids, 1000);
  EXPECT_EQ(options.kmeans_plus_plus_max_centroids, 5000);
  EXPECT_EQ(options.approximate_groups, 0);
  EXPECT_EQ(options.approximate_probes, 8);
  EXPECT_EQ(options.seeding, KMeansOptions::Seeding::kAuto);
}

// Exact search below approximate_min_centroids, approximate from there;
// k-means++ up to kmeans_plus_plus_max_centroids, random distinct seeds above.
TEST(KMeansOptionsTest, AutomaticChoicesFollowTheVocabularySize) {
  KMeansOptions options;
  options.num_centroids = 999;
  EXPECT_FALSE(options.UsesApproximateAssignment());
  EXPECT_TRUE(options.UsesKMeansPlusPlus());
  options.num_centroids = 2000;
  EXPECT_TRUE(options.UsesApproximateAssignment());
  EXPECT_TRUE(options.UsesKMeansPlusPlus());
  options.num_centroids = 5001;
  EXPECT_FALSE(options.UsesKMeansPlusPlus());
  options.num_centroids = 10000;
  EXPECT_TRUE(options.UsesApproximateAssignment());
  EXPECT_FALSE(options.UsesKMeansPlusPlus());
  EXPECT_EQ(options.ResolvedApproximateParams(), (ApproximateSearchParams{283, 8}));
  options.seeding = KMeansOptions::Seeding::kKMeansPlusPlus;
  EXPECT_TRUE(options.UsesKMeansPlusPlus());
  options.assignment = KMeansOptions::Assignment::kExact;
  EXPECT_FALSE(options.UsesApproximateAssignment());
  options.num_centroids = 10;
  options.assignment = KMeansOptions::Assignment::kApproximate;
  EXPECT_TRUE(options.UsesApproximateAssignment());
  EXPECT_EQ(options.ResolvedApproximateParams(), (ApproximateSearchParams{9, 8}));
}

TEST(KMeansOptionsTest, AssignmentNamesRoundTrip) {
  for (const auto a : {KMeansOptions::Assignment::kAuto, KMeansOptions::Assignment::kExact,
                       KMeansOptions::Assignment::kApproximate, KMeansOptions::Assignment::kTree}) {
    EXPECT_EQ(*ParseKMeansAssignment(KMeansAssignmentName(a)), a);
  }
  EXPECT_EQ(*ParseKMeansAssignment(""), KMeansOptions::Assignment::kAuto);
  EXPECT_THAT(ParseKMeansAssignment("fast").status().message(),
              ::testing::HasSubstr("must be 'auto', 'exact', 'approximate' or 'tree', got 'fast'"));
}

TEST(KMeansOptionsTest, RejectsBadFieldsNamingThem) {
  struct Case {
    void (*mutate)(KMeansOptions&);
    const char* message;
  };
  const Case cases[] = {
      {[](KMeansOptions& o) { o.num_centroids = 0; }, "num_centroids must be >= 1, got 0"},
      {[](KMeansOptions& o) { o.max_iterations = -3; }, "max_iterations must be >= 1, got -3"},
      {[](KMeansOptions& o) { o.tolerance = -0.5; }, "tolerance must be in [0, 1), got -0.5"},
      {[](KMeansOptions& o) { o.tolerance = std::nan(""); },
       "tolerance must be in [0, 1), got nan"},
      {[](KMeansOptions& o) { o.max_points_per_centroid = 0; },
       "max_points_per_centroid must be >= 1, got 0"},
      {[](KMeansOptions& o) { o.min_points_per_centroid = 0; },
       "min_points_per_centroid must be >= 1, got 0"},
      {[](KMeansOptions& o) { o.min_points_per_centroid = 300; },
       "min_points_per_centroid must be <= max_points_per_centroid (256), got 300"},
      {[](KMeansOptions& o) { o.init_points_per_centroid = 0; },
       "init_points_per_centroid must be >= 1, got 0"},
      {[](KMeansOptions& o) { o.assignment = static_cast<KMeansOptions::Assignment>(7); },
       "assignment must be kAuto, kExact, kApproximate or kTree, got 7"},
      {[](KMeansOptions& o) { o.tree_depth = 0; }, "tree_depth must be in [1, 8], got 0"},
      {[](KMeansOptions& o) { o.approximate_min_centroids = 0; },
       "approximate_min_centroids must be >= 1, got 0"},
      {[](KMeansOptions& o) { o.approximate_groups = -1; },
       "approximate_groups must be >= 0 (0: automatic), got -1"},
      {[](KMeansOptions& o) { o.approximate_groups = 1001; },
       "approximate_groups must be <= num_centroids (1000), got 1001"},
      {[](KMeansOptions& o) { o.approximate_probes = 0; },
       "approximate_probes must be >= 1, got 0"},
      {[](KMeansOptions& o) {
         o.approximate_groups = 4;
         o.approximate_probes = 5;
       },
       "approximate_probes must be <= approximate_groups (4), got 5"},
      {[](KMeansOptions& o) { o.seeding = static_cast<KMeansOptions::Seeding>(-1); },
       "seeding must be kAuto, kKMeansPlusPlus or kRandomDistinct, got -1"},
  };
  for (const Case& c : cases) {
    KMeansOptions options;
    c.mutate(options);
    const absl::Status status = options.Validate();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(status.message()), HasSubstr(c.message));
  }
}

TEST(TrainKMeansTest, RejectsBadInputWithTheValues) {
  const std::vector<float> points(12 * 4, 1.0f);
  KMeansOptions options;  // 1000 centroids
  absl::StatusOr<std::vector<float>> result = TrainKMeans(points.data(), 12, 4, options);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(result.status().message()),
              HasSubstr("got 12 training points for 1000 centroids"));

  options.num_centroids = 2;
  result = TrainKMeans(points.data(), 12, 0, options);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("dim must be >= 1, got 0"));

  result = TrainKMeans(static_cast<const float*>(nullptr), 12, 4, options);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("points is null"));

  options.num_centroids = 0;
  result = TrainKMeans(points.data(), 12, 4, options);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("num_centroids"));
}

TEST(TrainKMeansTest, RejectsNonFiniteCoordinates) {
  const KMeansOptions options = SmallOptions(2);
  for (float bad : {std::numeric_limits<float>::quiet_NaN(),
                    std::numeric_limits<float>::infinity(),
                    -std::numeric_limits<float>::infinity()}) {
    std::vector<float> points(10 * 3, 0.5f);
    points[7 * 3 + 2] = bad;
    const absl::StatusOr<std::vector<float>> result = TrainKMeans(points.data(), 10, 3, options);
    EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(result.status().message()),
                HasSubstr(absl::StrCat("point 7, coordinate 2 is ", bad)));
  }
}

TEST(TrainKMeansTest, RecoversWellSeparatedBlobs) {
  const std::size_t k = 12, dim = 16;
  const Blobs blobs = MakeBlobs(k, 200, dim, 7);
  KMeansReport report;
  const absl::StatusOr<std::vector<float>> centroids =
      TrainKMeans(blobs.points.data(), k * 200, dim, SmallOptions(k), &report);
  ASSERT_TRUE(centroids.ok()) << centroids.status();
  ASSERT_EQ(centroids->size(), k * dim);
  // Each true centre has its own centroid within a few standard errors
  // (sigma sqrt(dim / 200) = 0.28 for the mean of 200 points).
  std::set<std::size_t> matched;
  for (std::size_t c = 0; c < k; ++c) {
    std::size_t best = 0;
    double best_distance = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < k; ++j) {
      const double d = Distance(&blobs.centres[c * dim], &(*centroids)[j * dim], dim);
      if (d < best_distance) best_distance = d, best = j;
    }
    EXPECT_LT(best_distance, 1.0) << "centre " << c;
    matched.insert(best);
  }
  EXPECT_EQ(matched.size(), k);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.empty_clusters_split, 0u);
  // Mean squared distance to the true centre is about dim * sigma^2 = 16.
  EXPECT_NEAR(report.objective.back(), 16.0, 1.5);
  for (std::size_t i = 1; i < report.objective.size(); ++i) {
    EXPECT_LE(report.objective[i], report.objective[i - 1]) << "iteration " << i;
  }
}

TEST(TrainKMeansTest, IsDeterministicAndIndependentOfThreadCount) {
  // Enough points for many 128-point search tasks and k-means++ tasks, and
  // overlapping blobs so that Lloyd runs several iterations.
  const std::size_t k = 40, dim = 24;
  Blobs blobs = MakeBlobs(60, 100, dim, 11);
  for (float& v : blobs.points) v *= 0.05f;
  const std::size_t n = blobs.points.size() / dim;
  KMeansOptions options = SmallOptions(k);
  options.seed = 42;
  options.max_points_per_centroid = 100;  // sub-samples 4,000 of 6,000
  options.num_threads = 1;
  KMeansReport report1, report2;
  const auto one = TrainKMeans(blobs.points.data(), n, dim, options, &report1);
  const auto again = TrainKMeans(blobs.points.data(), n, dim, options);
  options.num_threads = 2;
  const auto two = TrainKMeans(blobs.points.data(), n, dim, options, &report2);
  ASSERT_TRUE(one.ok() && again.ok() && two.ok());
  EXPECT_EQ(*one, *again);
  EXPECT_EQ(*one, *two);  // bit-identical, not just close
  EXPECT_EQ(report1.objective, report2.objective);
  EXPECT_GT(report1.iterations, 2);
  EXPECT_EQ(report1.training_points, 4000u);

  options.seed = 43;
  const auto other = TrainKMeans(blobs.points.data(), n, dim, options);
  ASSERT_TRUE(other.ok());
  EXPECT_NE(*one, *other);
}

TEST(TrainKMeansTest, Uint8InputGivesTheSameCentroidsAsItsFloatValues) {
  const std::size_t n = 3000, dim = 32;
  std::mt19937 rng(5);
  std::vector<uint8_t> points(n * dim);
  for (uint8_t& v : points) v = static_cast<uint8_t>(rng() % 256);
  const std::vector<float> as_float(points.begin(), points.end());
  KMeansOptions options = SmallOptions(20);
  options.max_points_per_centroid = 100;
  const auto from_u8 = TrainKMeans(points.data(), n, dim, options);
  const auto from_float = TrainKMeans(as_float.data(), n, dim, options);
  ASSERT_TRUE(from_u8.ok() && from_float.ok());
  EXPECT_EQ(*from_u8, *from_float);
}

TEST(TrainKMeansTest, SplitsEmptyClustersOfDuplicatedData) {
  // Three distinct values for five centroids: seeding can find only three
  // distinct seeds, the other two start as duplicates and come out empty.
  const std::size_t dim = 4;
  const float values[3][dim] = {{1, 2, 3, 4}, {-5, 0, 5, 10}, {100, 100, 100, 100}};
  std::vector<float> points;
  for (int i = 0; i < 90; ++i) points.insert(points.end(), values[i % 3], values[i % 3] + dim);
  KMeansReport report;
  const auto centroids = TrainKMeans(points.data(), 90, dim, SmallOptions(5), &report);
  ASSERT_TRUE(centroids.ok()) << centroids.status();
  EXPECT_GT(report.empty_clusters_split, 0u);
  for (float v : *centroids) EXPECT_TRUE(std::isfinite(v));
  // Every value keeps a centroid on it (up to the 1/1024 split perturbation).
  for (const auto& value : values) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < 5; ++j)
      best = std::min(best, Distance(value, &(*centroids)[j * dim], dim));
    EXPECT_LT(best, 0.5);
  }
}

TEST(SplitEmptyClustersTest, SplitsTheLargestClusterFaissStyle) {
  const std::size_t dim = 2;
  std::vector<float> centroids = {1024, 2048, 0, 0, 512, 512, 0, 0};
  std::vector<std::size_t> counts = {9, 0, 9, 0};
  EXPECT_EQ(internal::SplitEmptyClusters(dim, &centroids, &counts), 2u);
  // Cluster 1 splits cluster 0 (largest, lowest index on the tie with 2); then
  // cluster 3 splits cluster 2, now the largest.
  EXPECT_EQ(counts, (std::vector<std::size_t>{5, 4, 5, 4}));
  EXPECT_EQ(centroids, (std::vector<float>{1023, 2050, 1025, 2046, 511.5, 512.5, 512.5, 511.5}));
}

TEST(TrainKMeansTest, SubSamplesAndReports) {
  const Blobs blobs = MakeBlobs(5, 400, 8, 3);
  KMeansOptions options = SmallOptions(5);
  options.max_points_per_centroid = 50;
  options.init_points_per_centroid = 4;
  KMeansReport report;
  ASSERT_TRUE(TrainKMeans(blobs.points.data(), 2000, 8, options, &report).ok());
  EXPECT_EQ(report.input_points, 2000u);
  EXPECT_EQ(report.training_points, 250u);
  EXPECT_EQ(report.init_points, 20u);
  EXPECT_EQ(report.objective.size(), static_cast<std::size_t>(report.iterations));
}

// A client that sends only KMeansTrainingRows' sample, with sampled_from,
// gets the centroids of the whole set, bit for bit (uint8 points, as the
// codebook service trains them; both seedings).
TEST(TrainKMeansTest, TheSampleAloneGivesTheWholeSetsCentroids) {
  const Blobs blobs = MakeBlobs(6, 500, 8, 5);
  const std::size_t n = 3000, dim = 8;
  std::vector<uint8_t> points(n * dim);
  for (std::size_t i = 0; i < points.size(); ++i) {
    points[i] = static_cast<uint8_t>(std::clamp(blobs.points[i] + 128.0f, 0.0f, 255.0f));
  }
  for (const auto seeding :
       {KMeansOptions::Seeding::kKMeansPlusPlus, KMeansOptions::Seeding::kRandomDistinct}) {
    KMeansOptions options = SmallOptions(6);
    options.max_points_per_centroid = 60;
    options.seeding = seeding;
    const std::vector<std::size_t> rows = KMeansTrainingRows(n, options);
    ASSERT_EQ(rows.size(), 360u);
    ASSERT_TRUE(std::is_sorted(rows.begin(), rows.end()));
    std::vector<uint8_t> sample;
    for (std::size_t r : rows) {
      sample.insert(sample.end(), points.begin() + r * dim, points.begin() + (r + 1) * dim);
    }
    KMeansReport whole_report, sample_report;
    const auto whole = TrainKMeans(points.data(), n, dim, options, &whole_report);
    KMeansOptions sampled = options;
    sampled.sampled_from = n;
    const auto from_sample = TrainKMeans(sample.data(), rows.size(), dim, sampled, &sample_report);
    ASSERT_TRUE(whole.ok() && from_sample.ok()) << from_sample.status();
    EXPECT_EQ(*whole, *from_sample);
    EXPECT_EQ(sample_report.input_points, n);
    EXPECT_EQ(sample_report.objective, whole_report.objective);
    // A "sample" of the wrong size, or of a set that needs none, is refused.
    EXPECT_EQ(TrainKMeans(sample.data(), rows.size() - 1, dim, sampled).status().code(),
              absl::StatusCode::kInvalidArgument);
    sampled.sampled_from = rows.size();
    EXPECT_EQ(TrainKMeans(sample.data(), rows.size(), dim, sampled).status().code(),
              absl::StatusCode::kInvalidArgument);
  }
  // A set no larger than the sample is all of it.
  KMeansOptions options = SmallOptions(6);
  options.max_points_per_centroid = 60;
  EXPECT_EQ(KMeansTrainingRows(300, options).size(), 300u);
}

KMeansOptions ApproximateOptions(int k) {
  KMeansOptions options = SmallOptions(k);
  options.assignment = KMeansOptions::Assignment::kApproximate;
  options.approximate_probes = 3;
  return options;
}

TEST(TrainKMeansTest, ApproximateAssignmentIsDeterministicAndIndependentOfThreadCount) {
  const std::size_t k = 150, dim = 16;
  Blobs blobs = MakeBlobs(200, 45, dim, 13);  // 9,000 points: three search blocks
  for (float& v : blobs.points) v *= 0.05f;
  const std::size_t n = blobs.points.size() / dim;
  KMeansOptions options = ApproximateOptions(k);
  options.seed = 9;
  options.max_iterations = 6;
  options.num_threads = 1;
  KMeansReport report1, report2;
  const auto one = TrainKMeans(blobs.points.data(), n, dim, options, &report1);
  const auto again = TrainKMeans(blobs.points.data(), n, dim, options);
  options.num_threads = 2;
  const auto two = TrainKMeans(blobs.points.data(), n, dim, options, &report2);
  ASSERT_TRUE(one.ok() && again.ok() && two.ok());
  EXPECT_EQ(*one, *again);
  EXPECT_EQ(*one, *two);
  EXPECT_EQ(report1.objective, report2.objective);
  EXPECT_TRUE(report1.approximate_assignment);
  EXPECT_EQ(report1.approximate, (ApproximateSearchParams{21, 3}));
  EXPECT_TRUE(report1.kmeans_plus_plus);  // k = 150 <= kmeans_plus_plus_max_centroids

  options.seed = 10;
  const auto other = TrainKMeans(blobs.points.data(), n, dim, options);
  ASSERT_TRUE(other.ok());
  EXPECT_NE(*one, *other);
}

// From the same (k-means++) seeds, approximate assignment reaches the
// objective of exact assignment on overlapping clusters, within 2%.
TEST(TrainKMeansTest, ApproximateAssignmentNearlyMatchesExactObjective) {
  const std::size_t k = 100, dim = 16;
  Blobs blobs = MakeBlobs(150, 40, dim, 17);
  for (float& v : blobs.points) v *= 0.05f;
  const std::size_t n = blobs.points.size() / dim;
  KMeansOptions approx = ApproximateOptions(k);
  approx.seeding = KMeansOptions::Seeding::kKMeansPlusPlus;
  approx.approximate_probes = 8;  // the default: 8 of 28 groups
  KMeansReport exact_report, approx_report;
  ASSERT_TRUE(TrainKMeans(blobs.points.data(), n, dim, SmallOptions(k), &exact_report).ok());
  ASSERT_TRUE(TrainKMeans(blobs.points.data(), n, dim, approx, &approx_report).ok());
  EXPECT_FALSE(exact_report.approximate_assignment);
  EXPECT_TRUE(approx_report.approximate_assignment);
  std::printf("objective: exact %.4f, approximate %.4f\n",
              exact_report.objective.back(),
              approx_report.objective.back());
  EXPECT_LE(approx_report.objective.back(), 1.02 * exact_report.objective.back());
}

TEST(TrainKMeansTest, RandomDistinctSeedingSkipsDuplicateValues) {
  // 90% of the points are one value (the all-zero descriptor); five distinct
  // others. Six centroids: random distinct seeding must take all six values
  // (a plain random draw would take mostly zeros), so each ends with a
  // centroid on it and nothing is split.
  const std::size_t dim = 3;
  std::vector<float> points;
  for (int i = 0; i < 450; ++i) points.insert(points.end(), {0.0f, 0.0f, 0.0f});
  for (int i = 0; i < 50; ++i) {
    const float v = static_cast<float>(10 * (1 + i % 5));
    points.insert(points.end(), {v, -v, v});
  }
  KMeansOptions options = SmallOptions(6);
  options.seeding = KMeansOptions::Seeding::kRandomDistinct;
  KMeansReport report;
  const auto centroids = TrainKMeans(points.data(), 500, dim, options, &report);
  ASSERT_TRUE(centroids.ok()) << centroids.status();
  EXPECT_EQ(report.empty_clusters_split, 0u);
  EXPECT_EQ(report.objective.front(), 0.0);
  std::set<float> firsts;
  for (std::size_t c = 0; c < 6; ++c) firsts.insert((*centroids)[c * dim]);
  EXPECT_EQ(firsts, (std::set<float>{0, 10, 20, 30, 40, 50}));
}

}  // namespace
}  // namespace meshseek
