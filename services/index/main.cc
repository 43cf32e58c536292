// meshseek-index: the histogram index and ranking. Flags: --data_dir, --postings_max_models,
// --threads and the server flags (common/rpc/server_main.h).
#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "common/rpc/server_main.h"
#include "services/index/index_grpc.h"

ABSL_FLAG(std::string, data_dir, "", "folder of the index database (required)");
ABSL_FLAG(int, threads, 0, "threads for ranking (0: all cores)");
ABSL_FLAG(std::size_t, postings_max_models, meshseek::IndexServiceOptions().postings_max_models,
          "a collection's postings are freed past this many models; its full scans then read "
          "the forward index (slower, the same distances)");

int main(int argc, char** argv) {
  meshseek::rpc::BlockTerminationSignals();
  absl::SetProgramUsageMessage("meshseek index service: histograms ranked by symmetric KL");
  absl::ParseCommandLine(argc, argv);
  meshseek::IndexServiceOptions options;
  options.data_dir = absl::GetFlag(FLAGS_data_dir);
  options.num_threads = absl::GetFlag(FLAGS_threads);
  options.postings_max_models = absl::GetFlag(FLAGS_postings_max_models);
  auto service = meshseek::IndexService::Create(options);
  if (!service.ok()) return meshseek::rpc::ExitWithError("index", service.status());
  meshseek::IndexGrpc grpc(service->get());
  return meshseek::rpc::ServeUntilSignal("index", {&grpc});
}
