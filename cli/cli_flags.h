// Every flag of the meshseek CLI, read once. The flags are defined in
// cli_flags.cc and nowhere else; main() parses the command line, reads them
// into a CliFlags and hands it to the command, which reads no flag itself
// (so that a command can be called, and tested, with values of its own).
// The pipeline parameters come with them (flags::ParamFlags,
// common/flags/pipeline_flags.h), the mesh limits as MeshReadOptions.
#ifndef MESHSEEK_CLI_CLI_FLAGS_H_
#define MESHSEEK_CLI_CLI_FLAGS_H_

#include <string>

#include "absl/status/statusor.h"
#include "cli/coordinator_client.h"
#include "cli/output_format.h"
#include "cli/web_gateway.h"
#include "common/eval/evaluation_report.h"
#include "common/flags/pipeline_flags.h"

namespace meshseek::cli {

struct CliFlags {
  flags::ParamFlags params;  // --method, --vocabulary, ..., --threads, --progress
  ClientOptions client;      // --server, --data_dir, --tls_*, --token_file, --reconnect_for,
                             // --max_mesh_*
  OutputFormat format = OutputFormat::kText;  // --format

  std::string collection;  // --collection
  std::string manifest;    // --manifest (eval, ingest)
  std::string folder;      // --folder (ingest)
  std::string out;         // --out (eval, report, synth, inspect)
  std::string job;         // --job (status)
  int top_k = 10;          // --top_k (query)
  int candidates = 0;      // --candidates (query)
  std::string image;       // --image (query by picture)
  int port = -1;           // --port (serve, web); -1: the command's default
  int metrics_port = 0;    // --metrics_port (serve)

  std::string eval_dir;            // --eval (report)
  EvaluationReportOptions report;  // --sample_queries, --top_results, --thumbnail_size, --threads
  int models_per_class = 0;        // --models_per_class (synth)
  int montage_images = 48;         // --montage_images (inspect)
  WebGatewayOptions web;           // --web_host, --web_upload_mb (port: PortOr)

  /// --port, or `fallback` when it is not given (serve and web listen on
  /// different ports by default).
  int PortOr(int fallback) const { return port < 0 ? fallback : port; }
};

/// The flags after absl::ParseCommandLine (flags::ParseCommandLineWithParams),
/// with `params` from it; InvalidArgument names a flag whose value is bad
/// (--format, a mesh limit).
absl::StatusOr<CliFlags> ReadCliFlags(const flags::ParamFlags& params);

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_CLI_FLAGS_H_
