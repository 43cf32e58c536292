// Parsing and validation of parameter values (pipeline_params.h); the table
// is pipeline_param_table.cc, JSON and --help text pipeline_params_text.cc.
#include "common/pipeline/pipeline_params.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

using Scope = ParamSpec::Scope;

// Parses and range-checks `text` as the spec's type.
absl::Status CheckValue(const ParamSpec& spec, absl::string_view text) {
  auto bad = [&]() {
    return absl::InvalidArgumentError(
        absl::StrCat("parameter ", spec.name, ": '", text, "' is not ", spec.TypeDescription()));
  };
  switch (spec.type) {
    case ParamType::kInt: {
      int v;
      if (!absl::SimpleAtoi(text, &v) || v < spec.min || v > spec.max) return bad();
      return absl::OkStatus();
    }
    case ParamType::kUint64: {
      uint64_t v;
      if (!absl::SimpleAtoi(text, &v) || static_cast<double>(v) < spec.min) return bad();
      return absl::OkStatus();
    }
    case ParamType::kDouble: {
      double v;
      if (!absl::SimpleAtod(text, &v) || !std::isfinite(v) || v < spec.min || v > spec.max) {
        return bad();
      }
      return absl::OkStatus();
    }
    case ParamType::kBool:
      if (text != "true" && text != "false") return bad();
      return absl::OkStatus();
    case ParamType::kChoice:
      for (const std::string& choice : spec.choices) {
        if (choice == text) return absl::OkStatus();
      }
      return bad();
    case ParamType::kDoubleList: {
      int count = 0;
      for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
        double v;
        if (++count > 8 || !absl::SimpleAtod(part, &v) || !std::isfinite(v) || v < spec.min ||
            v > spec.max) {
          return bad();
        }
      }
      return absl::OkStatus();
    }
  }
  return bad();
}

// "bfdsift+rld": each a known method, none twice, at most kMaxMethods.
absl::StatusOr<std::vector<FeatureMethod>> ParseMethods(absl::string_view method_list) {
  const ParamSpec& method_spec = PipelineParamSpecs().front();
  std::vector<FeatureMethod> methods;
  for (absl::string_view name : absl::StrSplit(method_list, '+')) {
    MESHSEEK_RETURN_IF_ERROR(CheckValue(method_spec, name));
    const FeatureMethod m = *ParseFeatureMethod(name);
    if (std::find(methods.begin(), methods.end(), m) != methods.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat("parameter method: '", name, "' is named twice in '", method_list, "'"));
    }
    methods.push_back(m);
  }
  if (methods.size() > CollectionOptions::kMaxMethods) {
    return absl::InvalidArgumentError(absl::StrCat("parameter method: at most ",
                                                   CollectionOptions::kMaxMethods,
                                                   " methods, got ",
                                                   methods.size()));
  }
  return methods;
}

}  // namespace

absl::StatusOr<CollectionOptions> CollectionOptionsFromValues(const ParamValues& values) {
  // The methods decide every other parameter's default and meaning.
  std::string method_list = kDefaultCollectionMethods;
  for (const auto& [name, value] : values) {
    if (name == "method") method_list = value;
  }
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<FeatureMethod> methods, ParseMethods(method_list));
  CollectionOptions options = CollectionOptions::ForMethods(methods);
  for (const auto& [name, value] : values) {
    if (name == "method") continue;
    // "rld.vocabulary": one method's; "vocabulary": every method's it applies to.
    absl::string_view plain = name;
    std::optional<FeatureMethod> only;
    if (const std::size_t dot = plain.find('.'); dot != absl::string_view::npos) {
      absl::StatusOr<FeatureMethod> m = ParseFeatureMethod(plain.substr(0, dot));
      if (!m.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("parameter ", name, ": ", m.status().message()));
      }
      if (std::find(methods.begin(), methods.end(), *m) == methods.end()) {
        return absl::InvalidArgumentError(absl::StrCat("parameter ",
                                                       name,
                                                       ": method ",
                                                       plain.substr(0, dot),
                                                       " is not in '",
                                                       method_list,
                                                       "'"));
      }
      only = *m;
      plain = plain.substr(dot + 1);
    }
    const ParamSpec* spec = FindPipelineParam(plain);
    if (spec == nullptr || spec->name == "method" ||
        (only.has_value() && spec->scope == Scope::kCollection)) {
      std::vector<std::string> known;
      for (const ParamSpec& s : PipelineParamSpecs()) known.push_back(s.name);
      return absl::InvalidArgumentError(
          absl::StrCat("unknown parameter '",
                       name,
                       "' (known: ",
                       absl::StrJoin(known, ", "),
                       "; a method's may be qualified: rld.vocabulary)"));
    }
    MESHSEEK_RETURN_IF_ERROR(CheckValue(*spec, value));
    if (spec->scope == Scope::kCollection) {
      spec->collection_set(value, &options);
      continue;
    }
    bool applied = false;
    for (RetrievalPipelineOptions& m : options.methods) {
      const FeatureMethod method = m.extractor.method;
      if ((only.has_value() && method != *only) || !spec->AppliesTo(method)) continue;
      spec->set(value, &m);
      applied = true;
    }
    if (!applied) {
      return absl::InvalidArgumentError(
          absl::StrCat("parameter ",
                       name,
                       " does not apply to method ",
                       only.has_value() ? FeatureMethodName(*only) : method_list.c_str(),
                       " (it applies to ",
                       spec->AppliesToText(),
                       ")"));
    }
  }
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  return options;
}

ParamValues CollectionValuesOf(const CollectionOptions& options) {
  ParamValues values;
  values.emplace_back("method", options.MethodName());
  for (const RetrievalPipelineOptions& m : options.methods) {
    const std::string prefix =
        options.fused() ? absl::StrCat(FeatureMethodName(m.extractor.method), ".") : "";
    for (const ParamSpec& spec : PipelineParamSpecs()) {
      if (spec.name != "method" && spec.AppliesTo(m.extractor.method)) {
        values.emplace_back(prefix + spec.name, spec.get(m));
      }
    }
  }
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    if (spec.scope != Scope::kCollection) continue;
    // Weights mean something with several methods; the re-ranking's own
    // parameters when it is on.
    if (spec.name == "weights" && !options.fused()) continue;
    if (absl::StartsWith(spec.name, "rerank_") && !options.rerank.enabled()) continue;
    values.emplace_back(spec.name, spec.collection_get(options));
  }
  return values;
}

absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromValues(const ParamValues& values) {
  ParamValues named = values;
  const bool method_named = std::any_of(values.begin(), values.end(),
                                        [](const auto& v) { return v.first == "method"; });
  if (!method_named) named.insert(named.begin(), {"method", kDefaultSingleMethod});
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionOptions options, CollectionOptionsFromValues(named));
  if (options.fused() || options.rerank.enabled()) {
    return absl::InvalidArgumentError(
        absl::StrCat("parameters of one method were expected, got '",
                     options.MethodName(),
                     "'",
                     options.rerank.enabled() ? " with re-ranking" : ""));
  }
  return options.methods.front();
}

ParamValues PipelineValuesOf(const RetrievalPipelineOptions& options) {
  return CollectionValuesOf(CollectionOptions::Of(options));
}

}  // namespace meshseek
