#include "common/pipeline/pipeline_params.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace meshseek {
namespace {

using ::testing::HasSubstr;

TEST(PipelineParamsTest, EveryMethodIsRegisteredOnceWithValidDefaults) {
  std::set<std::string> names;
  for (const FeatureMethodInfo& info : FeatureMethods()) {
    EXPECT_TRUE(names.insert(info.name).second) << info.name;
    EXPECT_EQ(&FeatureMethodInfoOf(info.method), &info);
    EXPECT_EQ(*ParseFeatureMethod(info.name), info.method);
    const RetrievalPipelineOptions options = RetrievalPipelineOptions::ForMethod(info.method);
    EXPECT_TRUE(options.Validate().ok()) << info.name << ": " << options.Validate();
    if (info.kind == DescriptorKind::kBagOfFeatures) {
      EXPECT_EQ(options.kmeans.num_centroids, info.vocabulary);
      EXPECT_EQ(options.kmeans.max_points_per_centroid, info.kmeans_points_per_centroid);
    } else {
      EXPECT_GT(info.descriptor_bytes, 0u);
      EXPECT_NE(info.distance, nullptr);
    }
  }
  EXPECT_FALSE(ParseFeatureMethod("sift").ok());
  // BF-DSIFT's codebook, measured (bench/results/bfdsift.txt).
  const RetrievalPipelineOptions bf = RetrievalPipelineOptions::ForMethod(FeatureMethod::kBfDsift);
  EXPECT_EQ(bf.kmeans.num_centroids, 40000);
  EXPECT_EQ(bf.kmeans.max_points_per_centroid, 40);
  EXPECT_EQ(bf.kmeans.max_iterations, 6);
  EXPECT_EQ(RetrievalPipelineOptions::ForMethod(FeatureMethod::kDldSift).kmeans.max_iterations, 25);
}

// RLD-SIFT alone keeps the paper's N_RLD and BF-DSIFT its 21-pixel patches;
// in a fusion RLD-SIFT resamples half as many points and BF-DSIFT's patches
// are 17 pixels (CollectionOptions::FusedMember); every other member is its
// method's own defaults, and a user's value still wins.
TEST(PipelineParamsTest, AFusionsRldSiftAndBfDsiftMembersAreLighter) {
  const auto alone = CollectionOptionsFromValues({{"method", "rld"}});
  ASSERT_TRUE(alone.ok()) << alone.status();
  EXPECT_EQ(alone->methods[0].extractor.rld.num_samples, 15000);
  EXPECT_EQ(alone->methods[0].kmeans.max_iterations, 25);
  const auto bf_alone = CollectionOptionsFromValues({{"method", "bfdsift"}});
  ASSERT_TRUE(bf_alone.ok()) << bf_alone.status();
  EXPECT_EQ(bf_alone->methods[0].extractor.bfdsift.patch_image.image_size, 21);
  const auto fused = CollectionOptionsFromValues({{"method", "bfdsift+rld+lsf+lfd"}});
  ASSERT_TRUE(fused.ok()) << fused.status();
  for (const RetrievalPipelineOptions& member : fused->methods) {
    const FeatureMethod method = member.extractor.method;
    if (method == FeatureMethod::kRldSift) {
      EXPECT_EQ(member.extractor.rld.num_samples, 7500);
      EXPECT_EQ(member.kmeans.max_iterations, 6);
    } else if (method == FeatureMethod::kBfDsift) {
      EXPECT_EQ(member.extractor.bfdsift.patch_image.image_size, 17);
    } else {
      EXPECT_EQ(PipelineValuesOf(member),
                PipelineValuesOf(RetrievalPipelineOptions::ForMethod(method)))
          << FeatureMethodName(method);
    }
  }
  const auto chosen =
      CollectionOptionsFromValues({{"method", "bfdsift+rld"}, {"rld.rld_samples", "15000"}});
  ASSERT_TRUE(chosen.ok()) << chosen.status();
  EXPECT_EQ(chosen->methods[1].extractor.rld.num_samples, 15000);
  const auto bf_chosen =
      CollectionOptionsFromValues({{"method", "bfdsift+rld"}, {"bfdsift.image_size", "21"}});
  ASSERT_TRUE(bf_chosen.ok()) << bf_chosen.status();
  EXPECT_EQ(bf_chosen->methods[0].extractor.bfdsift.patch_image.image_size, 21);
}

TEST(PipelineParamsTest, NamesAreUniqueAndEveryDefaultLiesInItsOwnRange) {
  std::set<std::string> names;
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    EXPECT_TRUE(names.insert(spec.name).second) << spec.name;
    EXPECT_FALSE(spec.doc.empty()) << spec.name;
    if (spec.scope == ParamSpec::Scope::kCollection) {
      for (const CollectionOptions& c :
           {CollectionOptions(),
            CollectionOptions::ForMethods({FeatureMethod::kRldSift, FeatureMethod::kLfd})}) {
        const std::string value = spec.collection_get(c);
        const auto back =
            CollectionOptionsFromValues({{"method", c.MethodName()}, {spec.name, value}});
        EXPECT_TRUE(back.ok()) << spec.name << " = " << value << ": " << back.status();
      }
      continue;
    }
    for (const FeatureMethodInfo& info : FeatureMethods()) {
      if (!spec.AppliesTo(info.method)) continue;
      const std::string value = spec.get(RetrievalPipelineOptions::ForMethod(info.method));
      // The default read back through the table is accepted by it.
      const auto options = PipelineOptionsFromValues({{"method", info.name}, {spec.name, value}});
      EXPECT_TRUE(options.ok()) << spec.name << " of " << info.name << " = " << value << ": "
                                << options.status();
    }
  }
  EXPECT_EQ(PipelineParamSpecs().front().name, "method");
}

TEST(PipelineParamsTest, ValuesRoundTripThroughTheCanonicalForm) {
  for (const FeatureMethodInfo& info : FeatureMethods()) {
    RetrievalPipelineOptions options = RetrievalPipelineOptions::ForMethod(info.method);
    options.kmeans.num_centroids = 77;
    options.kl.epsilon = 3.5e-9;
    const ParamValues values = PipelineValuesOf(options);
    const auto back = PipelineOptionsFromValues(values);
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_EQ(PipelineValuesOf(*back), values) << info.name;
    if (info.kind == DescriptorKind::kBagOfFeatures) {
      EXPECT_EQ(back->kmeans.num_centroids, 77);
      EXPECT_EQ(back->kl.epsilon, 3.5e-9);
    }
  }
}

TEST(PipelineParamsTest, SetsTheSelectedMethodsField) {
  const auto rld = PipelineOptionsFromValues(
      {{"method", "rld"}, {"levels", "7"}, {"scale_factor", "12.5"}, {"image_size", "17"}});
  ASSERT_TRUE(rld.ok()) << rld.status();
  EXPECT_EQ(rld->extractor.method, FeatureMethod::kRldSift);
  EXPECT_EQ(rld->extractor.rld.scale_space.levels, 7);
  EXPECT_EQ(rld->extractor.rld.scale_space.scale_factor, 12.5);
  EXPECT_EQ(rld->extractor.rld.depth_image.image_size, 17);
  EXPECT_EQ(rld->extractor.ld.scale_space.levels, ScaleSpaceOptions().levels);
  // The method may come after the values that depend on it.
  const auto dld = PipelineOptionsFromValues({{"points", "64"}, {"method", "dld"}});
  ASSERT_TRUE(dld.ok()) << dld.status();
  EXPECT_EQ(dld->extractor.dld.num_points, 64);
}

TEST(PipelineParamsTest, NoMethodIsTheFusionForACollectionAndDldForOneMethod) {
  const auto collection = CollectionOptionsFromValues({});
  ASSERT_TRUE(collection.ok()) << collection.status();
  EXPECT_EQ(collection->MethodName(), kDefaultCollectionMethods);
  EXPECT_EQ(collection->MethodName(), "bfdsift+rld+lsf+lfd");
  EXPECT_TRUE(collection->rerank.enabled());
  const auto one = PipelineOptionsFromValues({{"points", "64"}});
  ASSERT_TRUE(one.ok()) << one.status();
  EXPECT_EQ(one->extractor.method, FeatureMethod::kDldSift);
  EXPECT_EQ(one->extractor.dld.num_points, 64);
}

TEST(PipelineParamsTest, BadValuesAreRefusedNamingTheParameter) {
  auto error = [](const ParamValues& values) {
    const auto options = PipelineOptionsFromValues(values);
    return options.ok() ? std::string("ok") : std::string(options.status().message());
  };
  EXPECT_THAT(error({{"points", "many"}}), HasSubstr("parameter points: 'many' is not an integer"));
  EXPECT_THAT(error({{"points", "0"}}), HasSubstr("points"));
  EXPECT_THAT(error({{"points", "99999999999999999999"}}), HasSubstr("points"));
  EXPECT_THAT(error({{"scale", "nan"}}), HasSubstr("scale"));
  EXPECT_THAT(error({{"scale", "inf"}}), HasSubstr("scale"));
  EXPECT_THAT(error({{"weighted_frame", "1"}}), HasSubstr("true or false"));
  EXPECT_THAT(error({{"orientation", "left"}}), HasSubstr("one of dominant, up"));
  EXPECT_THAT(error({{"method", "sift"}}), HasSubstr("parameter method"));
  EXPECT_THAT(error({{"colour", "red"}}), HasSubstr("unknown parameter 'colour'"));
  EXPECT_THAT(error({{"method", "rld"}, {"points", "64"}}),
              HasSubstr("points does not apply to method rld"));
  // Struct validation still runs after the table's range checks.
  EXPECT_THAT(error({{"image_size", "20"}}), HasSubstr("odd"));
}

TEST(PipelineParamsTest, OneMethodRanksAloneAndSeveralAreFusedAndReranked) {
  const CollectionOptions one;
  EXPECT_TRUE(one.Validate().ok());
  EXPECT_EQ(one.MethodName(), "dld");
  EXPECT_FALSE(one.rescaled());
  const auto fused = CollectionOptionsFromValues({{"method", "bfdsift+rld+lsf+lfd"}});
  ASSERT_TRUE(fused.ok()) << fused.status();
  EXPECT_EQ(fused->MethodName(), "bfdsift+rld+lsf+lfd");
  // The strongest count double, LSF one and a half (bench/results/fusion.txt).
  EXPECT_EQ(fused->weights, (std::vector<double>{2, 2, 1.5, 1}));
  EXPECT_EQ(fused->methods[2].weighting.power, 0.5);  // LSF's square roots
  EXPECT_EQ(fused->rerank.method, RerankOptions::Method::kKReciprocal);
  EXPECT_EQ(fused->methods[0].kmeans.num_centroids, 40000);  // each method its own defaults
  EXPECT_EQ(fused->methods[1].kmeans.num_centroids, 2000);
  const RerankOptions rerank;
  EXPECT_EQ(rerank.k1, 20);
  EXPECT_EQ(rerank.k2, 4);
  EXPECT_EQ(rerank.lambda, 0.1);
  EXPECT_EQ(rerank.depth, 200);
}

TEST(PipelineParamsTest, PlainParametersSetEveryMethodTheyApplyToQualifiedOnesOne) {
  const auto c = CollectionOptionsFromValues({{"method", "rld+dld+lfd"},
                                              {"vocabulary", "500"},
                                              {"rld.vocabulary", "900"},
                                              {"image_size", "17"},
                                              {"weights", "2,1,0.5"},
                                              {"rerank_k1", "12"}});
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->methods[0].kmeans.num_centroids, 900);  // the later, qualified value
  EXPECT_EQ(c->methods[1].kmeans.num_centroids, 500);
  EXPECT_EQ(c->methods[0].extractor.rld.depth_image.image_size, 17);
  EXPECT_EQ(c->methods[1].extractor.dld.depth_image.image_size, 17);
  EXPECT_EQ(c->weights, (std::vector<double>{2, 1, 0.5}));
  EXPECT_EQ(c->rerank.k1, 12);
  // Canonical: every method's parameters qualified, then the collection's.
  const ParamValues values = CollectionValuesOf(*c);
  EXPECT_EQ(values.front(), (std::pair<std::string, std::string>{"method", "rld+dld+lfd"}));
  EXPECT_NE(std::find(values.begin(),
                      values.end(),
                      std::pair<std::string, std::string>{"dld.vocabulary", "500"}),
            values.end());
  auto back = CollectionOptionsFromValues(values);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(CollectionValuesOf(*back), values);
  // One method: plain names, the re-ranking named (none by default).
  const ParamValues single = CollectionValuesOf(CollectionOptions());
  EXPECT_EQ(single.back(), (std::pair<std::string, std::string>{"rerank", "none"}));
  EXPECT_EQ(PipelineValuesOf(RetrievalPipelineOptions()), single);
}

TEST(PipelineParamsTest, BadCollectionsAreRefusedNamingTheProblem) {
  auto error = [](const ParamValues& values) {
    const auto options = CollectionOptionsFromValues(values);
    return options.ok() ? std::string("ok") : std::string(options.status().message());
  };
  EXPECT_THAT(error({{"method", "rld+rld"}}), HasSubstr("'rld' is named twice"));
  EXPECT_THAT(error({{"method", "rld+sift"}}), HasSubstr("parameter method"));
  EXPECT_THAT(error({{"method", "rld+lfd"}, {"dld.points", "5"}}),
              HasSubstr("method dld is not in 'rld+lfd'"));
  EXPECT_THAT(error({{"method", "rld+lfd"}, {"lfd.vocabulary", "5"}}),
              HasSubstr("lfd.vocabulary does not apply to method lfd"));
  EXPECT_THAT(error({{"method", "rld+lfd"}, {"points", "5"}}),
              HasSubstr("points does not apply to method rld+lfd"));
  EXPECT_THAT(error({{"method", "rld+lfd"}, {"weights", "1"}}), HasSubstr("weights: 1 given"));
  EXPECT_THAT(error({{"method", "rld+lfd"}, {"weights", "0,0"}}), HasSubstr("every weight is 0"));
  EXPECT_THAT(error({{"rerank_k2", "500"}}), HasSubstr("k2 must be in"));
  EXPECT_THAT(error({{"method", "rld"}, {"rld.rerank", "none"}}),
              HasSubstr("unknown parameter 'rld.rerank'"));
  // A method's options from a collection of several are refused.
  EXPECT_THAT(PipelineOptionsFromValues({{"method", "rld+lfd"}}).status().message(),
              HasSubstr("one method"));
  EXPECT_TRUE(IsPipelineParamName("rld.vocabulary"));
  EXPECT_TRUE(IsPipelineParamName("rerank"));
  EXPECT_FALSE(IsPipelineParamName("rld.rerank"));
  EXPECT_FALSE(IsPipelineParamName("rld.method"));
  EXPECT_FALSE(IsPipelineParamName("server"));
}

TEST(PipelineParamsTest, JsonHasTypedValuesOfTheMethodsParametersOnly) {
  const std::string json = PipelineParamsToJson(RetrievalPipelineOptions()).Dump();
  EXPECT_THAT(json, HasSubstr("\"method\": \"dld\""));
  EXPECT_THAT(json, HasSubstr("\"points\": 1024"));
  EXPECT_THAT(json, HasSubstr("\"scale\": 0.2"));
  EXPECT_THAT(json, HasSubstr("\"weighted_frame\": true"));
  EXPECT_EQ(json.find("rld_samples"), std::string::npos) << json;
}

TEST(PipelineParamsTest, UsageListsEveryParameterWithItsDefaults) {
  const std::string usage = PipelineParamsUsage();
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    EXPECT_THAT(usage, HasSubstr("--" + spec.name + " ")) << spec.name;
  }
  EXPECT_THAT(usage, HasSubstr("rld 15, ld 20"));  // scale_factor's per-method defaults
}

}  // namespace
}  // namespace meshseek
