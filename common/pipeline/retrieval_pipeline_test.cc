#include "common/pipeline/retrieval_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "common/geometry/test_meshes.h"
#include "common/search/sparse_histogram.h"
#include "common/synth/synthetic_benchmark.h"

namespace meshseek {
namespace {

TEST(RetrievalPipelineOptionsTest, DefaultsArePinnedAndValid) {
  const RetrievalPipelineOptions options;
  EXPECT_TRUE(options.Validate().ok());
  EXPECT_EQ(options.extractor.method, FeatureMethod::kDldSift);
  EXPECT_EQ(options.kmeans.num_centroids, 2000);
  EXPECT_EQ(options.kmeans.max_points_per_centroid, 100);
  EXPECT_EQ(options.kl.epsilon, 1e-10);
  EXPECT_EQ(options.extractor.dld.scale, 0.2);
  EXPECT_TRUE(options.extractor.dld.weighted_frame);
  EXPECT_EQ(options.extractor.dld.frame_samples_per_support, 512);
  EXPECT_EQ(options.extractor.dld.descriptor.orientation, ImageOrientation::kDominant);
  const std::string json = options.ToJson().Dump();
  EXPECT_NE(json.find("\"vocabulary\": 2000"), std::string::npos) << json;
}

TEST(RetrievalPipelineOptionsTest, AVocabularyTheIndexCannotHoldIsRefused) {
  RetrievalPipelineOptions options;
  options.kmeans.num_centroids = static_cast<int>(kMaxVocabulary);
  EXPECT_TRUE(options.Validate().ok());
  options.kmeans.num_centroids = static_cast<int>(kMaxVocabulary) + 1;
  EXPECT_EQ(options.Validate().message(),
            "vocabulary size V = 65537 is more than the index's limit of 65536 words");
}

// A model and a rotated, scaled and moved copy of it get nearly the same
// bag-of-features histogram: their KL distance is under 5 % of the distance
// from the model to the nearest model of another class, and under 15 % of the
// nearest model of its own class.
TEST(RetrievalPipelineTest, HistogramDistancesAreInvariantToSimilarityTransforms) {
  SyntheticBenchmarkOptions synth;
  synth.models_per_class = 2;
  auto models = MakeSyntheticModels(synth);
  ASSERT_TRUE(models.ok()) << models.status();
  ExtractorOptions extractor;
  extractor.dld.num_points = 256;

  std::vector<LocalFeatures> features;
  for (const SyntheticModel& m : *models) {
    auto f = ExtractLocalFeatures(m.mesh, extractor);
    ASSERT_TRUE(f.ok()) << f.status();
    features.push_back(*std::move(f));
  }
  TriangleMesh moved = (*models)[0].mesh;
  TransformMesh(testing_meshes::AxisAngle(Vec3d(2, -1, 0.5), 2.7), 0.37, Vec3d(9, 1, -4), &moved);
  auto moved_features = ExtractLocalFeatures(moved, extractor);
  ASSERT_TRUE(moved_features.ok());

  RetrievalPipelineOptions options;
  options.kmeans.num_centroids = 64;
  auto codebook = TrainCollectionCodebook(features, options);
  ASSERT_TRUE(codebook.ok()) << codebook.status();
  features.push_back(*moved_features);
  auto histograms = EncodeCollection(*codebook, features, options);
  ASSERT_TRUE(histograms.ok());
  auto distances = SymmetricKlDistanceMatrix(*histograms, options.kl, 1);
  ASSERT_TRUE(distances.ok());
  const std::size_t n = histograms->size(), copy = n - 1;
  double same_class = 1e30, other_class = 1e30;
  for (std::size_t j = 1; j + 1 < n; ++j) {
    const double d = (*distances)[j];
    if ((*models)[j].label == (*models)[0].label) {
      same_class = std::min(same_class, d);
    } else {
      other_class = std::min(other_class, d);
    }
  }
  const double to_copy = (*distances)[copy];
  EXPECT_LT(to_copy, 0.05 * other_class) << "copy " << to_copy << ", other class " << other_class;
  EXPECT_LT(to_copy, 0.15 * same_class) << "copy " << to_copy << ", same class " << same_class;
}

TEST(RetrievalPipelineTest, EmptyCollectionIsAnError) {
  auto result = EvaluateMethod({}, RetrievalPipelineOptions());
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("no models"), absl::string_view::npos);
}

}  // namespace
}  // namespace meshseek

namespace meshseek {
namespace {

TEST(RankGlobalCollectionTest, IsTheMethodsOwnAllPairsMatrixAndRefusesOtherFeatures) {
  RetrievalPipelineOptions options = RetrievalPipelineOptions::ForMethod(FeatureMethod::kLfd);
  std::vector<LocalFeatures> features;
  std::vector<std::vector<uint8_t>> descriptors;
  for (const TriangleMesh& mesh :
       {testing_meshes::Cube(), testing_meshes::Icosphere(2), testing_meshes::Plane(4)}) {
    auto lfd = ExtractLfd(mesh, options.extractor.lfd);
    ASSERT_TRUE(lfd.ok()) << lfd.status();
    descriptors.push_back(*lfd);
    features.push_back(GlobalDescriptorFeatures(*lfd));
  }
  const auto matrix = RankGlobalCollection(features, options);
  ASSERT_TRUE(matrix.ok()) << matrix.status();
  EXPECT_EQ(*matrix, *LfdDistanceMatrix(descriptors, 1));
  features[1].dimension = 128;  // SIFT-sized: not an LFD descriptor
  EXPECT_EQ(RankGlobalCollection(features, options).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshseek
