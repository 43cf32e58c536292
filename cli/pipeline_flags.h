// Command-line flags for every retrieval-pipeline parameter, shared by the
// meshseek CLI and the bench tools so that a parameter has one flag, one help
// text and one default (the option struct's own). Flags become a
// PipelineParams message, and options come from that message by the same
// conversion the services use (rpc::PipelineOptionsFromParams).
#ifndef MESHSEEK_CLI_PIPELINE_FLAGS_H_
#define MESHSEEK_CLI_PIPELINE_FLAGS_H_

#include "absl/status/statusor.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "meshseek/v1/types.pb.h"

namespace meshseek::cli {

// The collection parameters from the flags: every field set (the flags'
// defaults are the core's), for CreateCollection and for the in-process path.
v1::PipelineParams PipelineParamsFromFlags();

// Options from the flags (--method, --scale, --points, --vocabulary, ...),
// validated: InvalidArgument names the bad flag and value.
absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromFlags();

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_PIPELINE_FLAGS_H_
