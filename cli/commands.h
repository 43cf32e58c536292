// The meshseek CLI commands. Each takes the flags main() read once
// (cli_flags.h), builds validated options and runs the core or talks to the
// coordinator (coordinator_client.h).
#ifndef MESHSEEK_CLI_COMMANDS_H_
#define MESHSEEK_CLI_COMMANDS_H_

#include <string>

#include "absl/status/status.h"
#include "cli/cli_flags.h"

namespace meshseek::cli {

// eval (eval_command.cc): --server=in-process runs the pipeline in this
// process; otherwise the models go through the coordinator, into the
// collection the flags make, or the existing one named by --collection.
absl::Status RunEval(const CliFlags& flags);
// The HTML report of an eval folder (report_command.cc).
absl::Status RunReport(const CliFlags& flags);
// The gRPC client commands (client_commands.cc).
absl::Status RunIngest(const CliFlags& flags);
absl::Status RunBuild(const CliFlags& flags);
absl::Status RunQuery(const CliFlags& flags, const std::string& model_path);
absl::Status RunStatus(const CliFlags& flags);
absl::Status RunServe(const CliFlags& flags);
absl::Status RunWeb(const CliFlags& flags);
absl::Status RunSynth(const CliFlags& flags);
absl::Status RunInspect(const CliFlags& flags, const std::string& model_path);

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_COMMANDS_H_
