// meshseek-codebook: trains, stores and applies visual vocabularies. Flags:
// --data_dir, --threads and the server flags (common/rpc/server_main.h).
#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "common/rpc/server_main.h"
#include "services/codebook/codebook_grpc.h"

ABSL_FLAG(std::string, data_dir, "", "folder of the codebook database (required)");
ABSL_FLAG(int, threads, 0, "threads for k-means and encoding (0: all cores)");

int main(int argc, char** argv) {
  meshseek::rpc::BlockTerminationSignals();
  absl::SetProgramUsageMessage("meshseek codebook service: train, store and encode vocabularies");
  absl::ParseCommandLine(argc, argv);
  meshseek::CodebookServiceOptions options;
  options.data_dir = absl::GetFlag(FLAGS_data_dir);
  options.num_threads = absl::GetFlag(FLAGS_threads);
  auto service = meshseek::CodebookService::Create(options);
  if (!service.ok()) return meshseek::rpc::ExitWithError("codebook", service.status());
  meshseek::CodebookGrpc grpc(service->get());
  return meshseek::rpc::ServeUntilSignal("codebook", {&grpc});
}
