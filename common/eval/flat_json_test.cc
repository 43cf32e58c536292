#include "common/eval/flat_json.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "common/base/json.h"

namespace meshseek {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Pair;

TEST(FlattenJsonTest, ReadsBackWhatJsonWrites) {
  Json json = Json::MakeObject();
  json.Set("queries", 255);
  Json& micro = json.Set("micro", Json::MakeObject());
  micro.Set("NN", 93.25);
  micro.Set("FT", 0.1);
  Json& params = json.Set("parameters", Json::MakeObject());
  params.Set("method", "rld");
  params.Set("distance", "symmetric \"KL\"\tdivergence");
  Json& weights = params.Set("weights", Json::MakeArray());
  weights.Push(1);
  weights.Push(0.5);
  params.Set("empty", Json::MakeArray());
  params.Set("exact", true);
  params.Set("none", nullptr);
  for (const int indent : {0, 2}) {
    auto flat = FlattenJson(json.Dump(indent), "metrics.json");
    ASSERT_TRUE(flat.ok()) << flat.status();
    EXPECT_THAT(*flat,
                ElementsAre(Pair("queries", "255"),
                            Pair("micro.NN", "93.25"),
                            Pair("micro.FT", "0.1"),
                            Pair("parameters.method", "rld"),
                            Pair("parameters.distance", "symmetric \"KL\"\tdivergence"),
                            Pair("parameters.weights", "[1, 0.5]"),
                            Pair("parameters.empty", "[]"),
                            Pair("parameters.exact", "true"),
                            Pair("parameters.none", "null")));
    EXPECT_EQ(FindFlatJson(*flat, "parameters.method"), "rld");
    EXPECT_EQ(std::stod(*FindFlatJson(*flat, "micro.NN")), 93.25);
    EXPECT_FALSE(FindFlatJson(*flat, "parameters").has_value());
  }
}

TEST(FlattenJsonTest, ArraysOfObjectsAreIndexedAndEscapesDecoded) {
  auto flat = FlattenJson(R"([{"a": 1}, [2, 3], "\u00e9\u0041"])", "x");
  ASSERT_TRUE(flat.ok()) << flat.status();
  EXPECT_THAT(*flat,
              ElementsAre(Pair("[0].a", "1"),
                          Pair("[1]", "[2, 3]"),
                          Pair("[2]",
                               "\xc3\xa9"
                               "A")));
}

TEST(FlattenJsonTest, MalformedInputNamesTheByte) {
  EXPECT_THAT(std::string(FlattenJson("{\"a\": 1,}", "m.json").status().message()),
              HasSubstr("m.json: byte 8: expected a key"));
  EXPECT_THAT(std::string(FlattenJson("{\"a\": 1} x", "m.json").status().message()),
              HasSubstr("content after the document"));
  EXPECT_THAT(std::string(FlattenJson("{\"a\": \"b", "m.json").status().message()),
              HasSubstr("unterminated string"));
  EXPECT_THAT(std::string(FlattenJson("{\"a\": nope}", "m.json").status().message()),
              HasSubstr("bad value 'nope'"));
  EXPECT_FALSE(FlattenJson("", "m.json").ok());
  EXPECT_THAT(std::string(FlattenJson(std::string(1000, '['), "m.json").status().message()),
              HasSubstr("nested too deeply"));
}

}  // namespace
}  // namespace meshseek
