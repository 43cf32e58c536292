// Pins everything the parameter table produces, as text, against
// testdata/pipeline_params.golden: the --help listing, every method's canonical
// values (what collections store and the services receive) and metrics.json
// parameter block, the default fusion's, and the validation messages users
// read. A change to the table that is meant to change any of these rewrites
// the file (MESHSEEK_UPDATE_GOLDEN=1 ctest -R pipeline_params_golden) and the
// diff is reviewed with the change; any other change must leave it alone.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "common/pipeline/pipeline_params.h"

namespace meshseek {
namespace {

constexpr char kGoldenPath[] = "testdata/pipeline_params.golden";

void AppendCollection(const std::string& title, const CollectionOptions& options,
                      std::string* out) {
  *out += "== " + title + ": values\n";
  for (const auto& [name, value] : CollectionValuesOf(options)) {
    *out += name + "=" + value + "\n";
  }
  *out += "== " + title + ": metrics.json parameters\n";
  for (const RetrievalPipelineOptions& m : options.methods) {
    *out += PipelineParamsToJson(m).Dump() + "\n";
  }
  Json collection = Json::MakeObject();
  AddCollectionParamsToJson(options, &collection);
  *out += collection.Dump() + "\n";
}

std::string Describe() {
  std::string out = "== usage\n" + PipelineParamsUsage();
  for (const FeatureMethodInfo& info : FeatureMethods()) {
    AppendCollection(info.name, CollectionOptions::ForMethods({info.method}), &out);
  }
  const CollectionOptions fused = *CollectionOptionsFromValues({{"method", "bfdsift+rld+lsf+lfd"}});
  AppendCollection("bfdsift+rld+lsf+lfd", fused, &out);
  const ParamValues refused[] = {
      {{"method", "rld"}, {"points", "5"}},
      {{"method", "dld"}, {"points", "0"}},
      {{"method", "dld"}, {"scale", "x"}},
      {{"method", "dld"}, {"orientation", "left"}},
      {{"method", "lsf"}, {"extra_scales", "0.3,,9"}},
      {{"method", "dld"}, {"sift", "1"}},
      {{"method", "dld+dld"}},
      {{"method", "bfdsift+rld"}, {"lsf.vocabulary", "10"}},
      {{"method", "bfdsift+rld"}, {"rld.weights", "1"}},
      {{"method", "lfd"}, {"vocabulary", "10"}},
      {{"method", "dld"}, {"rerank_k1", "1000"}},
  };
  out += "== refused\n";
  for (const ParamValues& values : refused) {
    out += std::string(CollectionOptionsFromValues(values).status().message()) + "\n";
  }
  return out;
}

TEST(PipelineParamsGoldenTest, TableOutputIsUnchanged) {
  const std::string actual = Describe();
  if (std::getenv("MESHSEEK_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(kGoldenPath) << actual;
    GTEST_SKIP() << "wrote " << kGoldenPath;
  }
  std::ifstream file(kGoldenPath);
  ASSERT_TRUE(file) << kGoldenPath << " is missing";
  std::stringstream golden;
  golden << file.rdbuf();
  // Line by line, so that a failure names the first line that differs.
  std::istringstream want(golden.str()), got(actual);
  std::string want_line, got_line;
  for (int line = 1;; ++line) {
    const bool more_want = static_cast<bool>(std::getline(want, want_line));
    const bool more_got = static_cast<bool>(std::getline(got, got_line));
    if (!more_want && !more_got) break;
    ASSERT_EQ(more_want ? want_line : "<end>", more_got ? got_line : "<end>")
        << kGoldenPath << ":" << line;
  }
}

}  // namespace
}  // namespace meshseek
