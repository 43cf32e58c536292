// Command-line flags for every retrieval-pipeline parameter, shared by the
// meshseek CLI and the bench tools. The flags are the parameter table of
// common/pipeline/pipeline_params.h: `--name=value` or `--name value` for
// every name there, with its type, range, per-method defaults and help
// generated from the table, so a new parameter needs no flag of its own.
// They become named values, and options come from those by the same
// conversion the services use (rpc::PipelineOptionsFromParams).
#ifndef MESHSEEK_CLI_PIPELINE_FLAGS_H_
#define MESHSEEK_CLI_PIPELINE_FLAGS_H_

#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/pipeline/collection_options.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "meshseek/v1/types.pb.h"

namespace meshseek::cli {

// Sets the program's usage message to `usage` and the parameter list, then
// absl::ParseCommandLine after taking the pipeline parameters out of argv
// (the table's names are not Abseil flags). Returns the positional
// arguments, argv[0] first.
std::vector<char*> ParseCommandLineWithParams(int argc, char** argv, absl::string_view usage);

// The collection parameters from the flags, canonical (every parameter,
// rpc::CollectionParamsToProto), for CreateCollection; or the error of
// CollectionOptionsFromFlags.
absl::StatusOr<v1::PipelineParams> CollectionParamsFromFlags();

// For a command on an existing collection (ingest): OK when every parameter
// flag given agrees with the collection's stored `params` (none given: the
// collection's own parameters apply); otherwise InvalidArgument naming each
// flag that conflicts (and the collection's value) or does not apply to it.
absl::Status CheckFlagsAgreeWith(const v1::PipelineParams& params, absl::string_view collection);

// Options from the parameter flags (--method, --scale, --points, --vocabulary,
// --rld.vocabulary, --weights, --rerank, ...) and --threads / --progress,
// validated: InvalidArgument names the bad parameter and value.
absl::StatusOr<CollectionOptions> CollectionOptionsFromFlags();

// The same for commands that work with one method (inspect, bench tools):
// InvalidArgument when the flags name several or ask for re-ranking.
absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromFlags();

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_PIPELINE_FLAGS_H_
