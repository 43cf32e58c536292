// meshseek-resample: the stateless resample worker. Flags: the server flags
// (common/rpc/server_main.h) and the mesh limits (common/flags/mesh_limit_flags.h).
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "common/flags/mesh_limit_flags.h"
#include "common/rpc/server_main.h"
#include "services/resample/resample_grpc.h"

int main(int argc, char** argv) {
  meshseek::rpc::BlockTerminationSignals();
  absl::SetProgramUsageMessage("meshseek resample worker: mesh -> Sobol point graph");
  absl::ParseCommandLine(argc, argv);
  auto limits = meshseek::flags::MeshLimitsFromFlags();
  if (!limits.ok()) return meshseek::rpc::ExitWithError("resample", limits.status());
  meshseek::ResampleService service(*limits);
  meshseek::ResampleGrpc grpc(&service);
  return meshseek::rpc::ServeUntilSignal("resample", {&grpc});
}
