#include "cli/commands.h"

namespace meshseek::cli {

absl::Status RunSynth() { return absl::UnimplementedError("synth: not yet built"); }

}  // namespace meshseek::cli
