// meshseek-extract: the stateless local-feature worker. Flags: --workers, the
// server flags (common/rpc/server_main.h) and the mesh limits
// (common/flags/mesh_limit_flags.h).
#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "common/flags/mesh_limit_flags.h"
#include "common/rpc/server_main.h"
#include "services/extract/extract_grpc.h"

ABSL_FLAG(int, workers, 0, "concurrent extractions (0: one per core)");

int main(int argc, char** argv) {
  meshseek::rpc::BlockTerminationSignals();
  absl::SetProgramUsageMessage("meshseek extract worker: mesh -> local features");
  absl::ParseCommandLine(argc, argv);
  meshseek::ExtractServiceOptions options;
  options.workers = absl::GetFlag(FLAGS_workers);
  auto limits = meshseek::flags::MeshLimitsFromFlags();
  if (!limits.ok()) return meshseek::rpc::ExitWithError("extract", limits.status());
  options.mesh_limits = *limits;
  if (absl::Status valid = options.Validate(); !valid.ok()) {
    return meshseek::rpc::ExitWithError("extract", valid);
  }
  meshseek::ExtractService service(options);
  meshseek::ExtractGrpc grpc(&service);
  return meshseek::rpc::ServeUntilSignal("extract", {&grpc});
}
