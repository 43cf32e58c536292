// Command-line flags for every retrieval-pipeline parameter, shared by the
// meshseek CLI and the bench tools. The flags are the parameter table of
// common/pipeline/pipeline_params.h: `--name=value` or `--name value` for
// every name there, with its type, range, per-method defaults and help
// generated from the table, so a new parameter needs no flag of its own.
// They become named values, and options come from those by the same
// conversion the services use (wire::PipelineOptionsFromParams).
//
// The command line is read once, by ParseCommandLineWithParams, into a
// ParamFlags value the program hands to what needs it: nothing here keeps
// state of its own.
#ifndef MESHSEEK_COMMON_FLAGS_PIPELINE_FLAGS_H_
#define MESHSEEK_COMMON_FLAGS_PIPELINE_FLAGS_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/pipeline/collection_options.h"
#include "common/pipeline/pipeline_params.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "meshseek/v1/types.pb.h"

namespace meshseek::flags {

// The pipeline parameters of one command line and its run flags.
struct ParamFlags {
  // `--name value` pairs of the parameter table, in the order given.
  ParamValues given;
  // The name of a last `--name` that had no value: an error reported when
  // options are asked for, naming it.
  std::string missing_value;
  // --threads (0: all cores) and --progress (bars on stderr).
  int threads = 0;
  bool progress = true;
};

struct CommandLine {
  // The positional arguments, argv[0] first (pointers into argv).
  std::vector<char*> positional;
  ParamFlags params;
};

// Sets the program's usage message to `usage` and the parameter list, then
// absl::ParseCommandLine after taking the pipeline parameters out of argv
// (the table's names are not Abseil flags).
CommandLine ParseCommandLineWithParams(int argc, char** argv, absl::string_view usage);

// Options from the parameter flags (--method, --scale, --points, --vocabulary,
// --rld.vocabulary, --weights, --rerank, ...) and --threads / --progress,
// validated: InvalidArgument names the bad parameter and value.
absl::StatusOr<CollectionOptions> CollectionOptionsFromFlags(const ParamFlags& flags);

// The same for commands that work with one method (inspect, bench tools):
// kDefaultSingleMethod when none is named; InvalidArgument when the flags
// name several or ask for re-ranking.
absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromFlags(const ParamFlags& flags);

// The collection parameters from the flags, canonical (every parameter,
// wire::CollectionParamsToProto), for CreateCollection; or the error of
// CollectionOptionsFromFlags.
absl::StatusOr<v1::PipelineParams> CollectionParamsFromFlags(const ParamFlags& flags);

// For a command on an existing collection (ingest): OK when every parameter
// flag given agrees with the collection's stored `params` (none given: the
// collection's own parameters apply); otherwise InvalidArgument naming each
// flag that conflicts (and the collection's value) or does not apply to it.
absl::Status CheckFlagsAgreeWith(const ParamFlags& flags,
                                 const v1::PipelineParams& params,
                                 absl::string_view collection);

}  // namespace meshseek::flags

#endif  // MESHSEEK_COMMON_FLAGS_PIPELINE_FLAGS_H_
