// meshseek-resample: the stateless resample worker. Flags: the server flags
// (common/rpc/server_main.h).
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "common/rpc/server_main.h"
#include "services/resample/resample_service.h"

int main(int argc, char** argv) {
  meshseek::rpc::BlockTerminationSignals();
  absl::SetProgramUsageMessage("meshseek resample worker: mesh -> Sobol point graph");
  absl::ParseCommandLine(argc, argv);
  meshseek::ResampleService service;
  return meshseek::rpc::ServeUntilSignal("resample", {&service});
}
