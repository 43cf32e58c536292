// meshseek: content-based 3-D shape retrieval from the command line.
//
//   meshseek eval  --manifest FILE --method dld --out DIR [options]
//   meshseek report --eval DIR [--out FILE]
//   meshseek synth --out DIR [--models_per_class N] [--seed S]
//   meshseek inspect MODEL --method ld|rld|dld --out DIR
//
// Flags are parsed here and only here, read once into CliFlags (cli_flags.h)
// and handed to the command, which builds validated options for the core
// (common/). See `meshseek --help`.
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
  query  Rank a collection's models by similarity to a mesh, or to a picture
         (PNG or JPEG: a photo, rendering or drawing of an object; needs lfd):
           meshseek query MODEL --collection C --top_k 10
           meshseek query --image PICTURE --collection C
  status List the collections, show one, or follow a job:
           meshseek status [--collection C | --job ID]
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
  namespace cli = meshseek::cli;
  const meshseek::flags::CommandLine line =
      meshseek::flags::ParseCommandLineWithParams(argc, argv, kUsage);
  const std::vector<char*>& args = line.positional;
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
  const absl::StatusOr<cli::CliFlags> flags = cli::ReadCliFlags(line.params);
  if (!flags.ok()) return Fail(flags.status());
  const std::string model = args.size() < 3 ? "" : args[2];
  cv::setNumThreads(0);  // meshseek parallelises across models itself
  absl::Status status;
  if (command == "eval") {
    status = cli::RunEval(*flags);
  } else if (command == "report") {
    status = cli::RunReport(*flags);
  } else if (command == "synth") {
    status = cli::RunSynth(*flags);
  } else if (command == "inspect") {
    status = model.empty() ? absl::InvalidArgumentError("inspect needs a MODEL file")
                           : cli::RunInspect(*flags, model);
  } else if (command == "ingest") {
    status = cli::RunIngest(*flags);
  } else if (command == "build") {
    status = cli::RunBuild(*flags);
  } else if (command == "query") {
    status = cli::RunQuery(*flags, model);
  } else if (command == "status") {
    status = cli::RunStatus(*flags);
  } else if (command == "serve") {
    status = cli::RunServe(*flags);
  } else if (command == "web") {
    status = cli::RunWeb(*flags);
  } else {
    status = absl::InvalidArgumentError(absl::StrCat(
        "unknown command '",
        command,
        "' (commands: eval, report, ingest, build, query, status, serve, web, synth, inspect)"));
  }
  return status.ok() ? 0 : Fail(status);
}
