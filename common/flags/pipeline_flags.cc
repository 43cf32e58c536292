#include "common/flags/pipeline_flags.h"

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/base/status_macros.h"
#include "common/pipeline/pipeline_params.h"
#include "common/wire/convert.h"

ABSL_FLAG(int, threads, 0, "threads (0: all cores)");
ABSL_FLAG(bool, progress, true, "show progress bars on stderr");

namespace meshseek::flags {

CommandLine ParseCommandLineWithParams(int argc, char** argv, absl::string_view usage) {
  CommandLine line;
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    const absl::string_view arg = argv[i];
    if (i == 0 || !absl::StartsWith(arg, "--") || arg == "--") {
      rest.push_back(argv[i]);
      continue;
    }
    absl::string_view name = arg.substr(2);
    std::string value;
    bool has_value = false;
    if (const std::size_t eq = name.find('='); eq != absl::string_view::npos) {
      value = std::string(name.substr(eq + 1));
      name = name.substr(0, eq);
      has_value = true;
    }
    if (!IsPipelineParamName(name)) {
      rest.push_back(argv[i]);
      continue;
    }
    if (!has_value) {
      if (i + 1 >= argc) {
        line.params.missing_value = std::string(name);
        continue;
      }
      value = argv[++i];
    }
    line.params.given.emplace_back(std::string(name), value);
  }
  absl::SetProgramUsageMessage(absl::StrCat(usage, "\n\n", PipelineParamsUsage()));
  int rest_argc = static_cast<int>(rest.size());
  rest.push_back(nullptr);
  line.positional = absl::ParseCommandLine(rest_argc, rest.data());
  line.params.threads = absl::GetFlag(FLAGS_threads);
  line.params.progress = absl::GetFlag(FLAGS_progress);
  return line;
}

namespace {

// The options of `values` with the run flags; errors name the flags.
absl::StatusOr<CollectionOptions> OptionsOf(const ParamFlags& flags, const ParamValues& values) {
  if (!flags.missing_value.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("--", flags.missing_value, " needs a value"));
  }
  absl::StatusOr<CollectionOptions> options = CollectionOptionsFromValues(values);
  if (!options.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("flags: ", options.status().message()));
  }
  options->SetRunOptions(flags.threads, flags.progress);
  return options;
}

}  // namespace

absl::StatusOr<CollectionOptions> CollectionOptionsFromFlags(const ParamFlags& flags) {
  return OptionsOf(flags, flags.given);
}

absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromFlags(const ParamFlags& flags) {
  // A command of one method that names none works with kDefaultSingleMethod.
  ParamValues values = flags.given;
  if (std::none_of(values.begin(), values.end(), [](const auto& v) { return v.first == "method"; })) {
    values.insert(values.begin(), {"method", kDefaultSingleMethod});
  }
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionOptions options, OptionsOf(flags, values));
  if (options.fused() || options.rerank.enabled()) {
    return absl::InvalidArgumentError(
        absl::StrCat("flags: this command works with one method, got --method ",
                     options.MethodName(),
                     options.rerank.enabled() ? " with --rerank" : ""));
  }
  return options.methods.front();
}

absl::StatusOr<v1::PipelineParams> CollectionParamsFromFlags(const ParamFlags& flags) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionOptions options, CollectionOptionsFromFlags(flags));
  v1::PipelineParams params;
  wire::CollectionParamsToProto(options, &params);
  return params;
}

absl::Status CheckFlagsAgreeWith(const ParamFlags& flags,
                                 const v1::PipelineParams& params,
                                 absl::string_view collection) {
  if (flags.given.empty()) return absl::OkStatus();
  if (!flags.missing_value.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("--", flags.missing_value, " needs a value"));
  }
  const auto value_in = [](const v1::PipelineParams& p,
                           const std::string& name) -> std::optional<std::string> {
    for (const v1::ParamValue& v : p.values()) {
      if (v.name() == name) return v.value();
    }
    return std::nullopt;
  };
  const auto conflict = [&](absl::string_view what) {
    return absl::InvalidArgumentError(absl::StrCat(
        "collection '", collection, "' exists with other parameters: ", what,
        ". Its own parameters apply to what is added: leave the flags out, or use another "
        "collection"));
  };
  // The flags read as they would be for this collection's methods (unless
  // they name others), both sides canonical: "--scale 0.10" agrees with 0.1.
  ParamValues values = flags.given;
  const bool method_given = std::any_of(values.begin(), values.end(),
                                        [](const auto& v) { return v.first == "method"; });
  if (!method_given && value_in(params, "method").has_value()) {
    values.insert(values.begin(), {"method", *value_in(params, "method")});
  }
  absl::StatusOr<CollectionOptions> options = CollectionOptionsFromValues(values);
  if (!options.ok()) return conflict(options.status().message());
  v1::PipelineParams given;
  wire::CollectionParamsToProto(*options, &given);
  std::vector<std::string> problems;
  for (const auto& [name, unused] : flags.given) {
    const std::optional<std::string> stored = value_in(params, name);
    const std::optional<std::string> asked = value_in(given, name);
    if (!stored.has_value()) {
      problems.push_back(absl::StrCat("--", name, " does not apply to it"));
    } else if (asked != stored) {
      problems.push_back(absl::StrCat("--", name, " ", asked.value_or("?"), " (it has ", name, "=",
                                      *stored, ")"));
    }
  }
  if (problems.empty()) return absl::OkStatus();
  return conflict(absl::StrJoin(problems, "; "));
}

}  // namespace meshseek::flags
