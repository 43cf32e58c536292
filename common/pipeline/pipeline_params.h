// The one description of every retrieval-pipeline parameter: its name, type,
// range or choices, documentation, the methods it applies to and where it
// lives in RetrievalPipelineOptions. Everything that names a parameter
// follows from this table: the CLI's flags and their help
// (cli/pipeline_flags), the collection parameters of the services
// (PipelineParams.values, rpc/convert), their validation and canonical form,
// and the parameter block of metrics.json. Adding a parameter is one entry in
// pipeline_params.cc (and its field in the method's option struct); a new
// method registers itself in common/features/local_feature_extractor.cc and
// lists its parameters here.
//
// Values travel as text ("1024", "0.2", "true", "dominant"), parsed by the
// parameter's type and checked against its range, so that a new parameter
// needs no new proto field. A parameter's default is its option struct's
// value for the selected method (a method may set its own defaults:
// FeatureMethodInfo::vocabulary), so the table never restates a default.
#ifndef MESHSEEK_COMMON_PIPELINE_PIPELINE_PARAMS_H_
#define MESHSEEK_COMMON_PIPELINE_PIPELINE_PARAMS_H_

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/base/json.h"
#include "common/pipeline/retrieval_pipeline.h"

namespace meshseek {

enum class ParamType { kInt, kUint64, kDouble, kBool, kChoice, kDoubleList };

struct ParamSpec {
  /// Flag, JSON and PipelineParams key: lower_snake_case.
  std::string name;
  ParamType type = ParamType::kInt;
  /// One line for --help; says what the value means and its unit.
  std::string doc;
  /// Inclusive range of numeric types (of each element of a kDoubleList,
  /// written "0.3,0.6", at most 8, may be empty).
  double min = 0;
  double max = 0;
  /// The accepted values of kChoice.
  std::vector<std::string> choices;
  /// Which methods it applies to: those listed, every bag-of-features
  /// method (codebook and ranking parameters), or all.
  enum class Scope { kListed, kBagOfFeatures, kAll };
  Scope scope = Scope::kListed;
  std::vector<FeatureMethod> methods;

  /// The value of options' selected method, canonical text.
  std::function<std::string(const RetrievalPipelineOptions&)> get;
  /// Sets an already parsed and range-checked value.
  std::function<void(absl::string_view, RetrievalPipelineOptions*)> set;

  bool AppliesTo(FeatureMethod method) const;
  /// "int in [1, 1000000]", "one of dominant, up", ...
  std::string TypeDescription() const;
};

/// Every parameter, in the order of --help and metrics.json. "method" comes
/// first: the others' defaults and meaning depend on it.
const std::vector<ParamSpec>& PipelineParamSpecs();
/// nullptr for an unknown name.
const ParamSpec* FindPipelineParam(absl::string_view name);

/// (name, value) pairs in the order given.
using ParamValues = std::vector<std::pair<std::string, std::string>>;

/// Options from named values: the method first (default dld), its defaults,
/// then every other value in order (a later value of the same name wins).
/// InvalidArgument naming the parameter for an unknown name, a value that does
/// not parse as its type or lies outside its range, or a parameter that does
/// not apply to the method; then RetrievalPipelineOptions::Validate.
absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromValues(const ParamValues& values);

/// Every parameter of options' method with its value, in table order: the
/// canonical form a collection stores (its meaning does not change when a
/// default does) and the input of PipelineOptionsFromValues.
ParamValues PipelineValuesOf(const RetrievalPipelineOptions& options);

/// The same as a JSON object of typed values, for metrics.json.
Json PipelineParamsToJson(const RetrievalPipelineOptions& options);

/// The parameter list for --help: name, type, the default of each method it
/// applies to, and its doc.
std::string PipelineParamsUsage();

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_PIPELINE_PIPELINE_PARAMS_H_
