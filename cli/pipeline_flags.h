// Command-line flags for every retrieval-pipeline parameter, shared by the
// meshseek CLI and the bench tools so that a parameter has one flag, one help
// text and one default (the option struct's own).
#ifndef MESHSEEK_CLI_PIPELINE_FLAGS_H_
#define MESHSEEK_CLI_PIPELINE_FLAGS_H_

#include "absl/status/statusor.h"
#include "common/pipeline/retrieval_pipeline.h"

namespace meshseek::cli {

// Options from the flags (--method, --scale, --points, --vocabulary, ...),
// validated: InvalidArgument names the bad flag and value.
absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromFlags();

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_PIPELINE_FLAGS_H_
