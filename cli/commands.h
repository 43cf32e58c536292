// The meshseek CLI commands. Each reads its flags (defined in its own .cc),
// builds validated options and runs the core.
#ifndef MESHSEEK_CLI_COMMANDS_H_
#define MESHSEEK_CLI_COMMANDS_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/pipeline/collection_evaluation.h"

namespace meshseek::cli {

absl::Status RunEval();
// The HTML report of an eval folder (report_command.cc).
absl::Status RunReport();
absl::Status RunIngest();
absl::Status RunBuild();
absl::Status RunQuery(const std::string& model_path);
absl::Status RunStatus();
absl::Status RunServe();
absl::Status RunWeb();

// eval's two paths: --server=in-process runs the pipeline in this process;
// otherwise the models go through the coordinator (client_commands.cc), into
// the collection the flags make, or the existing one named by --collection,
// whose own options then replace `options` (run options kept).
bool EvalInProcess();
absl::StatusOr<CollectionEvaluation> EvaluateThroughServices(
    const std::vector<ManifestEntry>& models,
    CollectionOptions* options,
    const std::string& manifest_path);
absl::Status RunSynth();
absl::Status RunInspect(const std::string& model_path);

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_COMMANDS_H_
