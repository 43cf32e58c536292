// meshseek-index: the histogram index and ranking. Flags: --data_dir,
// --threads and the server flags (common/rpc/server_main.h).
#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "common/rpc/server_main.h"
#include "services/index/index_service.h"

ABSL_FLAG(std::string, data_dir, "", "folder of the index database (required)");
ABSL_FLAG(int, threads, 0, "threads for ranking (0: all cores)");

int main(int argc, char** argv) {
  meshseek::rpc::BlockTerminationSignals();
  absl::SetProgramUsageMessage("meshseek index service: histograms ranked by symmetric KL");
  absl::ParseCommandLine(argc, argv);
  meshseek::IndexServiceOptions options;
  options.data_dir = absl::GetFlag(FLAGS_data_dir);
  options.num_threads = absl::GetFlag(FLAGS_threads);
  auto service = meshseek::IndexService::Create(options);
  if (!service.ok()) return meshseek::rpc::ExitWithError("index", service.status());
  return meshseek::rpc::ServeUntilSignal("index", {service->get()});
}
