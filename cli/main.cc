// meshseek: content-based 3-D shape retrieval from the command line.
//
//   meshseek eval  --manifest FILE --method dld --out DIR [options]
//   meshseek synth --out DIR [--models_per_class N] [--seed S]
//
// Flags are parsed here and only here, turned into validated option structs,
// and handed to the core (common/). See `meshseek --help`.
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli/commands.h"
#include "common/base/logging.h"

namespace {

constexpr char kUsage[] = R"(meshseek: 3-D shape retrieval with local depth-image SIFT features.

Commands:
  eval   Extract local features of every model of a labelled collection, learn a
         codebook on them, rank all pairs by symmetric KL divergence and evaluate:
           meshseek eval --manifest FILE --method dld --out DIR
         writes DIR/distances.bin (N x N float32, manifest order) and
         DIR/metrics.json, and prints the metrics table.
  synth  Write the built-in labelled synthetic benchmark (procedural shapes):
           meshseek synth --out DIR
         writes DIR/manifest.csv, DIR/synthetic.cla and DIR/models/.

Run `meshseek --helpfull` for every flag.)";

int Fail(const absl::Status& status) {
  std::fprintf(stderr, "meshseek: error: %s\n", std::string(status.message()).c_str());
  return status.code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage(kUsage);
  std::vector<char*> args = absl::ParseCommandLine(argc, argv);
  if (args.size() < 2) {
    std::fprintf(stderr, "%s\n", kUsage);
    return 2;
  }
  if (args.size() > 2) {
    return Fail(absl::InvalidArgumentError(
        absl::StrCat("unexpected argument '", args[2], "' (options are --flags)")));
  }
  cv::setNumThreads(0);  // meshseek parallelises across models itself
  const std::string command = args[1];
  absl::Status status;
  if (command == "eval") {
    status = meshseek::cli::RunEval();
  } else if (command == "synth") {
    status = meshseek::cli::RunSynth();
  } else {
    status = absl::InvalidArgumentError(
        absl::StrCat("unknown command '", command, "' (commands: eval, synth)"));
  }
  return status.ok() ? 0 : Fail(status);
}
