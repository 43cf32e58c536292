#include "common/pipeline/pipeline_params.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
  EXPECT_EQ(bf.kmeans.max_points_per_centroid, 50);
}

TEST(PipelineParamsTest, NamesAreUniqueAndEveryDefaultLiesInItsOwnRange) {
  std::set<std::string> names;
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    EXPECT_TRUE(names.insert(spec.name).second) << spec.name;
    EXPECT_FALSE(spec.doc.empty()) << spec.name;
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
