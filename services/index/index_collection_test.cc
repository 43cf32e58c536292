// IndexCollection: the first model chooses the engine; later ones must fit
// it (the only one may replace itself with another kind); answers come in
// (ordinal, model id) order whatever the arrival order, over either engine.
#include "services/index/index_collection.h"

#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace meshseek {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

ModelSignature Histogram(uint32_t vocabulary, std::vector<uint32_t> words) {
  ModelSignature signature;
  signature.histogram.vocabulary = vocabulary;
  signature.histogram.words = std::move(words);
  signature.histogram.weights.assign(signature.histogram.words.size(),
                                     1.0f / signature.histogram.words.size());
  return signature;
}

ModelSignature Descriptor(char fill) {
  ModelSignature signature;
  signature.descriptor.emplace();
  signature.descriptor->set_method("lfd");
  signature.descriptor->set_data(
      std::string(FeatureMethodInfoOf(FeatureMethod::kLfd).descriptor_bytes, fill));
  return signature;
}

TEST(IndexCollectionTest, FirstModelChoosesAndOthersMustFit) {
  IndexCollection collection;
  ASSERT_TRUE(collection.Place("a", 0, "x", Histogram(8, {1, 2})).ok());
  EXPECT_THAT(collection.CheckFits("b", Histogram(16, {1})).message(), HasSubstr("size 16"));
  EXPECT_THAT(collection.CheckFits("b", Descriptor(1)).message(),
              HasSubstr("the collection holds histograms"));
  EXPECT_EQ(collection.Place("b", 1, "x", Descriptor(1)).code(), absl::StatusCode::kInvalidArgument);
  // The only model may replace itself with another kind.
  ASSERT_TRUE(collection.Place("a", 0, "x", Descriptor(1)).ok());
  EXPECT_EQ(collection.size(), 1u);
  EXPECT_FALSE(collection.epsilon().has_value());
  EXPECT_THAT(collection.CheckFits("b", Histogram(8, {1})).message(),
              HasSubstr("the collection holds global descriptors"));
}

TEST(IndexCollectionTest, HistogramsInOrderAndRanked) {
  IndexCollection collection;
  ASSERT_TRUE(collection.Place("c", 2, "y", Histogram(8, {5, 6})).ok());
  ASSERT_TRUE(collection.Place("a", 0, "x", Histogram(8, {1, 2})).ok());
  ASSERT_TRUE(collection.Place("b", 1, "x", Histogram(8, {1, 3})).ok());
  EXPECT_THAT(collection.ModelIds(), ElementsAre("a", "b", "c"));
  absl::StatusOr<std::vector<IndexCollection::Hit>> hits =
      collection.Search(Histogram(8, {1, 2}), 2, 0, 1);
  ASSERT_TRUE(hits.ok()) << hits.status();
  ASSERT_EQ(hits->size(), 2u);
  EXPECT_EQ((*hits)[0].model->model_id, "a");
  EXPECT_EQ((*hits)[0].distance, 0.0f);
  EXPECT_EQ((*hits)[1].model->model_id, "b");

  google::protobuf::RepeatedPtrField<std::string> subset;
  subset.Add("c");
  subset.Add("a");
  subset.Add("a");
  subset.Add("unknown");
  v1::DistancesResponse response;
  ASSERT_TRUE(collection.Distances({Histogram(8, {1, 2})}, subset, 1, &response).ok());
  EXPECT_THAT(response.model_ids(), ElementsAre("a", "c"));
  ASSERT_EQ(response.distances_size(), 2);
  EXPECT_EQ(response.distances(0), 0.0f);
  EXPECT_GT(response.distances(1), 0.0f);

  EXPECT_TRUE(collection.Remove("a"));
  EXPECT_FALSE(collection.Remove("a"));
  const std::vector<v1::IndexedModel> exported = collection.Export();
  ASSERT_EQ(exported.size(), 2u);
  EXPECT_EQ(exported[0].model_id(), "b");
  EXPECT_THAT(exported[0].histogram().bins(), ElementsAre(1, 3));
}

TEST(IndexCollectionTest, EpsilonChangeKeepsEveryModel) {
  IndexCollection collection;
  ASSERT_TRUE(collection.Place("a", 0, "", Histogram(8, {1})).ok());
  ASSERT_TRUE(collection.Place("b", 1, "", Histogram(8, {2})).ok());
  const float before = (*collection.Search(Histogram(8, {1}), 2, 0, 1))[1].distance;
  ASSERT_TRUE(collection.SetEpsilon(1e-3).ok());
  EXPECT_EQ(collection.epsilon(), 1e-3);
  absl::StatusOr<std::vector<IndexCollection::Hit>> after =
      collection.Search(Histogram(8, {1}), 2, 0, 1);
  ASSERT_TRUE(after.ok());
  ASSERT_EQ(after->size(), 2u);
  EXPECT_LT((*after)[1].distance, before);  // a larger zero-bin value: a nearer stranger
}

TEST(IndexCollectionTest, DescriptorsExportedAndRefusedAsHistograms) {
  IndexCollection collection;
  ASSERT_TRUE(collection.Place("b", 1, "", Descriptor(2)).ok());
  ASSERT_TRUE(collection.Place("a", 0, "", Descriptor(1)).ok());
  const std::vector<v1::IndexedModel> exported = collection.Export();
  ASSERT_EQ(exported.size(), 2u);
  EXPECT_EQ(exported[0].model_id(), "a");
  EXPECT_EQ(exported[0].global_descriptor().method(), "lfd");
  v1::DistancesResponse response;
  // An empty histogram is a stranger only to histograms.
  const absl::Status refused =
      collection.Distances({Histogram(8, {})}, {}, 1, &response);
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.message(), HasSubstr("query 0"));
}

// Neighbors and PairDistances: a query held here (by id) answers as the same
// model given whole; over either engine.
void ExpectNeighborsOfHeldAndWholeAgree(IndexCollection& collection,
                                        const std::vector<ModelSignature>& signatures) {
  for (std::size_t i = 0; i < signatures.size(); ++i) {
    const std::string id(1, static_cast<char>('a' + i));
    const IndexCollection::Query held{id, std::nullopt};
    const IndexCollection::Query whole{id, signatures[i]};
    const auto by_id = collection.Neighbors(held, 2, 0);
    const auto given = collection.Neighbors(whole, 2, 0);
    ASSERT_TRUE(by_id.ok() && given.ok()) << by_id.status() << given.status();
    ASSERT_EQ(by_id->size(), 2u);
    ASSERT_EQ(given->size(), 2u);
    EXPECT_EQ((*by_id)[0].model->model_id, id);  // itself first, at 0
    EXPECT_EQ((*by_id)[0].distance, 0.0f);
    for (std::size_t j = 0; j < 2; ++j) {
      EXPECT_EQ((*by_id)[j].model, (*given)[j].model);
      EXPECT_EQ((*by_id)[j].distance, (*given)[j].distance);
    }
    google::protobuf::RepeatedPtrField<std::string> targets;
    targets.Add("c");
    targets.Add("unknown");
    targets.Add("a");
    const auto pairs = collection.PairDistances(held, targets);
    ASSERT_TRUE(pairs.ok()) << pairs.status();
    ASSERT_EQ(pairs->size(), 2u);  // the unknown id left out, in (ordinal, id) order
    EXPECT_EQ((*pairs)[0].model->model_id, "a");
    EXPECT_EQ((*pairs)[1].model->model_id, "c");
    const auto search = collection.Search(signatures[i], 3, 0, 1);
    for (const IndexCollection::Hit& hit : *search) {
      for (const IndexCollection::Hit& pair : *pairs) {
        if (pair.model == hit.model) EXPECT_EQ(pair.distance, hit.distance);
      }
    }
  }
  const auto stranger = collection.Neighbors({"zz", std::nullopt}, 1, 0);
  EXPECT_EQ(stranger.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(stranger.status().message(), HasSubstr("'zz'"));
}

TEST(IndexCollectionTest, NeighborsAndPairDistancesOfHistograms) {
  IndexCollection collection;
  const std::vector<ModelSignature> signatures = {Histogram(8, {1, 2}), Histogram(8, {1, 3}),
                                                  Histogram(8, {5, 6})};
  for (std::size_t i = 0; i < signatures.size(); ++i) {
    ASSERT_TRUE(collection.Place(std::string(1, 'a' + i), i, "", signatures[i]).ok());
  }
  ExpectNeighborsOfHeldAndWholeAgree(collection, signatures);
  const auto misfit = collection.Neighbors({"q", Histogram(16, {1})}, 1, 0);
  EXPECT_EQ(misfit.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(misfit.status().message(), HasSubstr("query 'q'"));
}

TEST(IndexCollectionTest, NeighborsAndPairDistancesOfDescriptors) {
  IndexCollection collection;
  const std::vector<ModelSignature> signatures = {Descriptor(1), Descriptor(2), Descriptor(9)};
  for (std::size_t i = 0; i < signatures.size(); ++i) {
    ASSERT_TRUE(collection.Place(std::string(1, 'a' + i), i, "", signatures[i]).ok());
  }
  ExpectNeighborsOfHeldAndWholeAgree(collection, signatures);
}

TEST(IndexCollectionTest, ExportsASubsetWithOrWithoutSignatures) {
  IndexCollection collection;
  ASSERT_TRUE(collection.Place("b", 1, "y", Histogram(8, {1, 3})).ok());
  ASSERT_TRUE(collection.Place("a", 0, "x", Histogram(8, {1, 2})).ok());
  google::protobuf::RepeatedPtrField<std::string> ids;
  ids.Add("b");
  ids.Add("gone");
  ids.Add("a");
  const std::vector<v1::IndexedModel> bare = collection.Export(ids, /*signatures=*/false);
  ASSERT_EQ(bare.size(), 2u);
  EXPECT_EQ(bare[0].model_id(), "a");
  EXPECT_EQ(bare[0].label(), "x");
  EXPECT_FALSE(bare[0].has_histogram());
  const std::vector<v1::IndexedModel> full = collection.Export(ids);
  ASSERT_EQ(full.size(), 2u);
  EXPECT_EQ(full[1].model_id(), "b");
  EXPECT_THAT(full[1].histogram().bins(), ElementsAre(1, 3));
}

TEST(IndexCollectionTest, APicturesViewSearchesViewsOnly) {
  IndexCollection views;
  ASSERT_TRUE(views.Place("c", 2, "y", Descriptor(9)).ok());
  ASSERT_TRUE(views.Place("a", 0, "x", Descriptor(1)).ok());
  ASSERT_TRUE(views.Place("b", 1, "x", Descriptor(5)).ok());
  const std::string view(FeatureMethodInfoOf(FeatureMethod::kLfd).view_bytes, 5);
  absl::StatusOr<std::vector<IndexCollection::Hit>> hits = views.SearchView(view, 3, 1);
  ASSERT_TRUE(hits.ok()) << hits.status();
  ASSERT_EQ(hits->size(), 3u);
  // b's views are the picture's; a and c differ by 4 in each of 45 bytes.
  EXPECT_EQ((*hits)[0].model->model_id, "b");
  EXPECT_EQ((*hits)[0].distance, 0);
  EXPECT_EQ((*hits)[1].model->model_id, "a");
  EXPECT_EQ((*hits)[1].distance, 180);
  EXPECT_EQ((*hits)[2].model->model_id, "c");
  EXPECT_THAT(views.SearchView("short", 3, 1).status().message(), HasSubstr("5 bytes"));
  IndexCollection histograms;
  ASSERT_TRUE(histograms.Place("a", 0, "x", Histogram(8, {1, 2})).ok());
  EXPECT_THAT(histograms.SearchView(view, 3, 1).status().message(),
              HasSubstr("cannot be searched by a picture"));
}

}  // namespace
}  // namespace meshseek
