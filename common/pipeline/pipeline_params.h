// The one description of every retrieval-pipeline parameter: its name, type,
// range or choices, documentation, the methods it applies to and where it
// lives in RetrievalPipelineOptions (a method's parameters) or
// CollectionOptions (fusion and re-ranking). Everything that names a parameter
// follows from this table: the CLI's flags and their help
// (common/flags/pipeline_flags), the collection parameters of the services
// (PipelineParams.values, wire/convert), their validation and canonical form,
// and the parameter block of metrics.json. Adding a parameter is one row of
// the table in pipeline_param_table.cc (and its field in the method's option
// struct); a new method registers itself in
// common/features/local_feature_extractor.cc and names itself in the rows of
// its parameters. Parsing and validation are pipeline_params.cc, metrics.json
// and --help pipeline_params_text.cc; testdata/pipeline_params.golden pins
// what all three produce (pipeline_params_golden_test).
//
// Values travel as text ("1024", "0.2", "true", "dominant"), parsed by the
// parameter's type and checked against its range, so that a new parameter
// needs no new proto field.
//
// Several methods. "method" may name several, joined by '+'
// ("bfdsift+rld+lfd": a fused collection). A method's parameter then applies
// to every named method it applies to ("vocabulary" to each bag-of-features
// method), or to one when qualified by the method's name ("rld.vocabulary");
// the canonical form of a fused collection qualifies every one. Collection
// parameters (weights, rerank, ...) are never qualified. A parameter's default is its option
// struct's value for the selected method (a method may set its own defaults:
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
#include "common/pipeline/collection_options.h"
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
  /// method (codebook and ranking parameters), or all; or none, being a
  /// parameter of the collection (fusion, re-ranking).
  enum class Scope { kListed, kBagOfFeatures, kAll, kCollection };
  Scope scope = Scope::kListed;
  std::vector<FeatureMethod> methods;

  /// The value of options' selected method, canonical text.
  std::function<std::string(const RetrievalPipelineOptions&)> get;
  /// Sets an already parsed and range-checked value.
  std::function<void(absl::string_view, RetrievalPipelineOptions*)> set;
  /// kCollection: the same on the collection's options.
  std::function<std::string(const CollectionOptions&)> collection_get;
  std::function<void(absl::string_view, CollectionOptions*)> collection_set;

  bool AppliesTo(FeatureMethod method) const;
  /// "dld, lsf", "bag-of-features methods", "every method", "the collection".
  std::string AppliesToText() const;
  /// "int in [1, 1000000]", "one of dominant, up", ...
  std::string TypeDescription() const;
};

/// Every parameter, in the order of --help and metrics.json. "method" comes
/// first: the others' defaults and meaning depend on it; the collection's
/// parameters come last.
const std::vector<ParamSpec>& PipelineParamSpecs();
/// nullptr for an unknown name.
const ParamSpec* FindPipelineParam(absl::string_view name);
/// Whether `name` is a parameter, plain or qualified by a method's name
/// ("rld.vocabulary"); the command line takes these out of argv.
bool IsPipelineParamName(absl::string_view name);

/// (name, value) pairs in the order given.
using ParamValues = std::vector<std::pair<std::string, std::string>>;

/// The methods of a collection or an evaluation that names none: the four
/// fused and re-ranked, the best configuration measured (first tier 94.1 on
/// McGill and 61.9 on PSB train, against 75.0 and 37.6 for dld; its costs
/// beside each method's in docs/results.md, "What each method costs").
inline constexpr char kDefaultCollectionMethods[] = "bfdsift+rld+lsf+lfd";
/// The method of what works with one method (a service's extraction, inspect,
/// synth's seed) and names none, and of a stored collection that predates
/// named values: the fastest local method.
inline constexpr char kDefaultSingleMethod[] = "dld";

/// Options from named values: the methods first (default
/// kDefaultCollectionMethods), their defaults, then every other value in order (a later value of the same name
/// wins). InvalidArgument naming the parameter for an unknown name, a value
/// that does not parse as its type or lies outside its range, a parameter
/// that applies to no method named (or a qualified one to a method not
/// named), a method named twice; then CollectionOptions::Validate.
absl::StatusOr<CollectionOptions> CollectionOptionsFromValues(const ParamValues& values);

/// Every parameter of the collection with its value: the canonical form a
/// collection stores (its meaning does not change when a default does) and
/// the input of CollectionOptionsFromValues. One method: its parameters as
/// plain names, then "rerank" (and its own parameters when enabled); several:
/// every method's parameters qualified, then "weights" and the re-ranking.
ParamValues CollectionValuesOf(const CollectionOptions& options);

/// One method's options from values that name one method (its canonical
/// values, or a collection's without fusion or re-ranking; none named:
/// kDefaultSingleMethod): what the extract and codebook services read.
/// InvalidArgument as above, or for several methods or enabled re-ranking.
absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromValues(const ParamValues& values);
/// The canonical values of `options` as a collection of its own (no fusion,
/// no re-ranking): what the coordinator gives a fused collection's member
/// collections and the extract and codebook services.
ParamValues PipelineValuesOf(const RetrievalPipelineOptions& options);

/// One method's parameters as a JSON object of typed values, for metrics.json.
Json PipelineParamsToJson(const RetrievalPipelineOptions& options);
/// Adds the collection's parameters (weights of a fused collection, the
/// re-ranking) to a JSON object.
void AddCollectionParamsToJson(const CollectionOptions& options, Json* json);

/// The parameter list for --help: name, type, the default of each method it
/// applies to, and its doc.
std::string PipelineParamsUsage();

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_PIPELINE_PIPELINE_PARAMS_H_
