// meshseek: content-based 3-D shape retrieval from the command line.
//
//   meshseek eval  --manifest FILE --method dld --out DIR [options]
//   meshseek report --eval DIR [--out FILE]
//   meshseek synth --out DIR [--models_per_class N] [--seed S]
//   meshseek inspect MODEL --method ld|rld|dld --out DIR
//
// Flags are parsed here and only here, turned into validated option structs,
// and handed to the core (common/). See `meshseek --help`.
#include <cstdio>
#include <iostream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli/commands.h"
#include "cli/pipeline_flags.h"
#include "common/base/logging.h"

namespace {

constexpr char kUsage[] = R"(meshseek: 3-D shape retrieval with local depth-image SIFT features.

Every command below talks gRPC to a coordinator: --server HOST:PORT (with
--tls_ca CA.pem and --token_file FILE when it wants TLS and a token), or, by
default, an embedded stack of all services started for the command with its
state in --data_dir (default ./meshseek-data).

Commands:
  eval   Ingest every model of a labelled collection, learn a codebook on their
         local features, index them, rank all pairs by symmetric KL divergence
         and evaluate:
           meshseek eval --manifest FILE --method dld --out DIR
         writes DIR/distances.bin (N x N float32, manifest order),
         DIR/models.csv and DIR/metrics.json, and prints the metrics table.
         --server in-process runs the same pipeline without services (the
         benchmark reference).
  report Write one self-contained HTML page about an eval run: metrics,
         first tier per class, precision-recall curves, sample queries' top
         results as thumbnails:
           meshseek report --eval DIR [--out DIR/report.html]
  ingest Add models to a collection (created with the method flags if new):
           meshseek ingest --collection C --manifest FILE | --folder DIR
  build  Train the collection's codebook and index every model:
           meshseek build --collection C
  query  Rank a collection's models by similarity to a mesh:
           meshseek query MODEL --collection C --top_k 10
  status Show a collection, or follow a job: meshseek status --collection C | --job ID
  serve  Run the embedded stack until Ctrl-C: meshseek serve --port 50051
         [--tls_cert C --tls_key K [--tls_ca CA] [--token_file T]] [--metrics_port 9464]
  web    Serve the query page (pick a collection, drop a mesh, see the ranked
         thumbnails) until Ctrl-C: meshseek web --server HOST:PORT --port 8080
         (without --server, on an embedded stack on --data_dir)
  synth  Write the built-in labelled synthetic benchmark (procedural shapes):
           meshseek synth --out DIR
         writes DIR/manifest.csv, DIR/synthetic.cla and DIR/models/.
  inspect  Show what a method detects and renders on one model:
           meshseek inspect MODEL --method rld --out DIR
         writes DIR/points.ply (feature points coloured by level), DIR/points.png
         (the model with its visible feature points) and DIR/depth_images.png.

status, query and eval take --format json: one JSON document on stdout for
programs (the proto's field names; eval's is metrics.json).

Run `meshseek --helpfull` for every flag.)";

int Fail(const absl::Status& status) {
  std::fprintf(stderr, "meshseek: error: %s\n", std::string(status.message()).c_str());
  return status.code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> args = meshseek::cli::ParseCommandLineWithParams(argc, argv, kUsage);
  if (args.size() < 2) {
    std::fprintf(stderr, "%s\n", kUsage);
    return 2;
  }
  const std::string command = args[1];
  const std::size_t positional = command == "inspect" || command == "query" ? 3 : 2;
  if (args.size() > positional) {
    return Fail(absl::InvalidArgumentError(
        absl::StrCat("unexpected argument '", args[positional], "' (options are --flags)")));
  }
  cv::setNumThreads(0);  // meshseek parallelises across models itself
  absl::Status status;
  if (command == "eval") {
    status = meshseek::cli::RunEval();
  } else if (command == "report") {
    status = meshseek::cli::RunReport();
  } else if (command == "synth") {
    status = meshseek::cli::RunSynth();
  } else if (command == "inspect") {
    status = args.size() < 3 ? absl::InvalidArgumentError("inspect needs a MODEL file")
                             : meshseek::cli::RunInspect(args[2]);
  } else if (command == "ingest") {
    status = meshseek::cli::RunIngest();
  } else if (command == "build") {
    status = meshseek::cli::RunBuild();
  } else if (command == "query") {
    status = meshseek::cli::RunQuery(args.size() < 3 ? "" : args[2]);
  } else if (command == "status") {
    status = meshseek::cli::RunStatus();
  } else if (command == "serve") {
    status = meshseek::cli::RunServe();
  } else if (command == "web") {
    status = meshseek::cli::RunWeb();
  } else {
    status = absl::InvalidArgumentError(absl::StrCat(
        "unknown command '",
        command,
        "' (commands: eval, report, ingest, build, query, status, serve, web, synth, inspect)"));
  }
  return status.ok() ? 0 : Fail(status);
}
