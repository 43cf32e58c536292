// metrics.json's parameter block and the --help listing, from the parameter
// table (pipeline_params.h).
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/pipeline/param_value_text.h"
#include "common/pipeline/pipeline_params.h"

namespace meshseek {
namespace {

using Scope = ParamSpec::Scope;
using Options = RetrievalPipelineOptions;

// Sets json[spec.name] to `text` as the spec's type.
void SetTyped(const ParamSpec& spec, const std::string& text, Json* json) {
  switch (spec.type) {
    case ParamType::kInt:
    case ParamType::kUint64: {
      int64_t v = 0;
      if (absl::SimpleAtoi(text, &v)) {
        json->Set(spec.name, v);
      } else {
        json->Set(spec.name, text);  // a uint64 beyond int64: exact as text
      }
      break;
    }
    case ParamType::kDouble: {
      double v = 0;
      (void)absl::SimpleAtod(text, &v);
      json->Set(spec.name, v);
      break;
    }
    case ParamType::kBool:
      json->Set(spec.name, text == "true");
      break;
    case ParamType::kChoice:
      json->Set(spec.name, text);
      break;
    case ParamType::kDoubleList: {
      Json& list = json->Set(spec.name, Json::MakeArray());
      std::vector<double> values;
      param_text::Parse(text, &values);
      for (double v : values) list.Push(v);
      break;
    }
  }
}

}  // namespace

Json PipelineParamsToJson(const RetrievalPipelineOptions& options) {
  Json json = Json::MakeObject();
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    if (spec.AppliesTo(options.extractor.method)) SetTyped(spec, spec.get(options), &json);
  }
  return json;
}

void AddCollectionParamsToJson(const CollectionOptions& options, Json* json) {
  for (const auto& [name, value] : CollectionValuesOf(options)) {
    const ParamSpec* spec = FindPipelineParam(name);
    if (spec != nullptr && spec->scope == Scope::kCollection) SetTyped(*spec, value, json);
  }
}

std::string PipelineParamsUsage() {
  std::string usage =
      "Pipeline parameters (--name=value; each applies to the methods named; with several\n"
      "methods, --rld.vocabulary=3000 sets one method's):\n";
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    if (spec.scope == Scope::kCollection) {
      // Defaults for one method and for several (a fusion).
      const std::string one = spec.collection_get(CollectionOptions());
      const std::string several = spec.collection_get(
          CollectionOptions::ForMethods({FeatureMethod::kBfDsift, FeatureMethod::kRldSift}));
      std::string value =
          one == several ? one : absl::StrCat("one method ", one, ", several ", several);
      if (spec.name == "weights") {
        std::vector<std::string> own;
        for (const FeatureMethodInfo& m : FeatureMethods()) {
          own.push_back(absl::StrCat(m.name, " ", m.fusion_weight));
        }
        value = absl::StrCat("each method's own: ", absl::StrJoin(own, ", "));
      }
      absl::StrAppend(&usage,
                      "  --",
                      spec.name,
                      "  ",
                      spec.TypeDescription(),
                      "; ",
                      spec.doc,
                      "\n      the collection; default: ",
                      value,
                      "\n");
      continue;
    }
    // "default: 20" when every method has the same, else "default: rld 15, ld 20";
    // "rld 15000 (7500 fused)" where a fusion's member differs.
    std::vector<std::string> defaults;
    std::set<std::string> distinct;
    for (const FeatureMethodInfo& info : FeatureMethods()) {
      if (spec.name == "method" || !spec.AppliesTo(info.method)) continue;
      std::string value = spec.get(Options::ForMethod(info.method));
      const std::string fused = spec.get(CollectionOptions::FusedMember(info.method));
      if (fused != value) absl::StrAppend(&value, " (", fused, " fused)");
      defaults.push_back(absl::StrCat(info.name, " ", value));
      distinct.insert(value);
    }
    if (distinct.size() == 1) defaults = {*distinct.begin()};
    absl::StrAppend(&usage, "  --", spec.name, "  ", spec.TypeDescription(), "; ", spec.doc, "\n");
    if (spec.name == "method") {
      absl::StrAppend(&usage, "      default: ", kDefaultCollectionMethods,
                      " (fused, re-ranked); a command of one method: ", kDefaultSingleMethod, "\n");
    } else {
      absl::StrAppend(
          &usage, "      ", spec.AppliesToText(), "; default: ", absl::StrJoin(defaults, ", "), "\n");
    }
  }
  return usage;
}

}  // namespace meshseek
