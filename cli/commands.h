// The meshseek CLI commands. Each reads its flags (defined in its own .cc),
// builds validated options and runs the core.
#ifndef MESHSEEK_CLI_COMMANDS_H_
#define MESHSEEK_CLI_COMMANDS_H_

#include <string>

#include "absl/status/status.h"

namespace meshseek::cli {

absl::Status RunEval();
absl::Status RunSynth();
absl::Status RunInspect(const std::string& model_path);

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_COMMANDS_H_
