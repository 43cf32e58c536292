#include "common/pipeline/collection_evaluation.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "absl/strings/str_cat.h"
#include "common/base/file_io.h"
#include "common/eval/distance_matrix.h"
#include "common/pipeline/pipeline_params.h"
#include "common/search/fusion.h"
#include "common/synth/synthetic_benchmark.h"

namespace meshseek {
namespace {

// A symmetric n x n matrix with zero diagonal, values in [0, scale).
std::vector<float> RandomMatrix(std::size_t n, float scale, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, scale);
  std::vector<float> d(n * n, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) d[i * n + j] = d[j * n + i] = u(rng);
  }
  return d;
}

CollectionOptions TwoMethods() {
  return CollectionOptions::ForMethods({FeatureMethod::kLsf, FeatureMethod::kLfd});
}

TEST(CombineMethodDistancesTest, OneMethodWithoutRerankingKeepsItsOwnDistances) {
  const std::vector<float> d = RandomMatrix(20, 30.0f, 1);
  std::vector<double> scales;
  auto combined = CombineMethodDistances({d}, 20, CollectionOptions(), &scales);
  ASSERT_TRUE(combined.ok());
  EXPECT_EQ(*combined, d);
  EXPECT_EQ(scales, std::vector<double>{1.0});
}

TEST(CombineMethodDistancesTest, FusionIsTheWeightedMeanOfRescaledDistances) {
  const std::size_t n = 30;
  const std::vector<float> a = RandomMatrix(n, 20.0f, 2), b = RandomMatrix(n, 3000.0f, 3);
  CollectionOptions options = TwoMethods();
  options.weights = {1.0, 3.0};
  options.rerank.method = RerankOptions::Method::kNone;
  std::vector<double> scales;
  auto fused = CombineMethodDistances({a, b}, n, options, &scales);
  ASSERT_TRUE(fused.ok()) << fused.status();
  double mean_a = 0, mean_b = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      if (i == j) continue;
      mean_a += a[i * n + j];
      mean_b += b[i * n + j];
    }
  }
  mean_a /= n * (n - 1);
  mean_b /= n * (n - 1);
  EXPECT_NEAR(scales[0], mean_a, 1e-9 * mean_a);
  EXPECT_NEAR(scales[1], mean_b, 1e-9 * mean_b);
  for (std::size_t k = 0; k < n * n; ++k) {
    EXPECT_NEAR((*fused)[k], (a[k] / mean_a + 3 * b[k] / mean_b) / 4, 1e-5);
  }
  // Re-ranked: the graph of the fused distances, re-ranked as RerankMatrix.
  options.rerank.method = RerankOptions::Method::kKReciprocal;
  auto reranked = CombineMethodDistances({a, b}, n, options, &scales);
  ASSERT_TRUE(reranked.ok());
  auto graph = NeighborGraph::FromMatrix(*fused, n, options.rerank.graph_k());
  EXPECT_EQ(*reranked, *RerankMatrix(*graph, *fused, options.rerank));
}

TEST(CombineMethodDistancesTest, MismatchedInputsAreRefused) {
  std::vector<double> scales;
  const std::vector<float> d = RandomMatrix(4, 1.0f, 4);
  EXPECT_FALSE(CombineMethodDistances({d}, 4, TwoMethods(), &scales).ok());
  EXPECT_FALSE(CombineMethodDistances({d, std::vector<float>(15)}, 4, TwoMethods(), &scales).ok());
}

TEST(EvaluateCollectionTest, AFusedCollectionCombinesItsMethodsEvaluatedAlone) {
  const std::string dir = ::testing::TempDir() + "/meshseek_collection_eval";
  std::filesystem::remove_all(dir);
  SyntheticBenchmarkOptions synth;
  synth.models_per_class = 3;
  ASSERT_TRUE(GenerateSyntheticBenchmark(synth, dir).ok());
  auto models = ReadManifest(dir + "/manifest.csv");
  ASSERT_TRUE(models.ok());
  auto options = CollectionOptionsFromValues({{"method", "lsf+lfd"},
                                              {"points", "128"},
                                              {"vocabulary", "64"},
                                              {"view_size", "64"},
                                              {"rerank_k1", "4"},
                                              {"rerank_k2", "2"}});
  ASSERT_TRUE(options.ok()) << options.status();
  options->SetRunOptions(2, false);
  auto fused = EvaluateCollection(*models, *options);
  ASSERT_TRUE(fused.ok()) << fused.status();
  ASSERT_EQ(fused->methods.size(), 2u);
  EXPECT_EQ(fused->metrics.queries, models->size());

  // Each method alone gives the matrix the fusion started from.
  std::vector<absl::Span<const float>> matrices;
  for (std::size_t m = 0; m < 2; ++m) {
    auto alone = EvaluateMethod(*models, options->methods[m]);
    ASSERT_TRUE(alone.ok());
    EXPECT_EQ(alone->distances, fused->methods[m].distances);
    matrices.push_back(fused->methods[m].distances);
  }
  std::vector<double> scales;
  EXPECT_EQ(*CombineMethodDistances(matrices, models->size(), *options, &scales), fused->distances);
  EXPECT_EQ(fused->methods[1].scale, scales[1]);

  ASSERT_TRUE(WriteEvaluation(*fused, *options, dir + "/eval").ok());
  auto read = ReadFileToString(dir + "/eval/metrics.json");
  ASSERT_TRUE(read.ok());
  const std::string& json = *read;
  for (const char* key : {"\"method\": \"lsf+lfd\"",
                          "\"lsf\": {",
                          "\"weights\": [",
                          "\"rerank\": \"kreciprocal\"",
                          "\"distance_scales\"",
                          "\"rerank_k1\": 4"}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << "\n" << json;
  }
  // The models in matrix order, with absolute paths, for `meshseek report`.
  auto listed = ReadManifest(dir + "/eval/models.csv");
  ASSERT_TRUE(listed.ok()) << listed.status();
  ASSERT_EQ(listed->size(), models->size());
  for (std::size_t i = 0; i < models->size(); ++i) {
    EXPECT_EQ((*listed)[i].id, (*models)[i].id);
    EXPECT_EQ((*listed)[i].label, (*models)[i].label);
    EXPECT_TRUE(std::filesystem::path((*listed)[i].path).is_absolute()) << (*listed)[i].path;
    EXPECT_TRUE(std::filesystem::equivalent((*listed)[i].path, (*models)[i].path));
  }
  // Each method's own matrix beside the fused one, for the ablation.
  for (std::size_t m = 0; m < 2; ++m) {
    const std::string method(FeatureMethodName(fused->methods[m].method));
    auto matrix =
        ReadDistanceMatrix(absl::StrCat(dir, "/eval/distances.", method, ".bin"), models->size());
    ASSERT_TRUE(matrix.ok()) << method << ": " << matrix.status();
    EXPECT_EQ(*matrix, fused->methods[m].distances) << method;
  }
}

}  // namespace
}  // namespace meshseek
