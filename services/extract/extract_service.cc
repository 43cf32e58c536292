#include "services/extract/extract_service.h"

#include <algorithm>
#include <optional>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/features/local_feature_extractor.h"
#include "common/wire/convert.h"

namespace meshseek {

absl::Status ExtractServiceOptions::Validate() const {
  if (workers > 1024) {
    return absl::InvalidArgumentError(absl::StrCat("extract workers must be <= 1024, got ", workers));
  }
  return mesh_limits.Validate();
}

ExtractService::ExtractService(const ExtractServiceOptions& options)
    : workers_(options.workers > 0 ? options.workers
                                   : std::max(1u, std::thread::hardware_concurrency())),
      mesh_limits_(options.mesh_limits) {}

absl::StatusOr<v1::ExtractResponse> ExtractService::Extract(const v1::ExtractRequest& request,
                                                            const rpc::CallContext& call) {
  // Every error names the model it is about.
  const std::string where =
      request.model_id().empty() ? "" : absl::StrCat("model ", request.model_id(), ": ");
  auto fail = [&where](const absl::Status& status) { return Prefixed(status, where); };
  // Parse and check everything before taking a slot.
  absl::StatusOr<RetrievalPipelineOptions> options =
      wire::PipelineOptionsFromParams(request.params());
  if (!options.ok()) return fail(options.status());
  absl::StatusOr<TriangleMesh> mesh = wire::MeshFromProto(request.mesh(), mesh_limits_);
  if (!mesh.ok()) return fail(mesh.status());
  options->extractor.num_threads = CappedThreads(request.threads(), workers_);
  std::optional<PointGraph> graph;
  if (request.has_resampled() && options->extractor.method == FeatureMethod::kRldSift) {
    absl::StatusOr<PointGraph> parsed = wire::GraphFromProto(request.resampled());
    if (!parsed.ok()) return fail(parsed.status());
    graph = *std::move(parsed);
  }
  {
    absl::MutexLock lock(&mutex_);
    auto free_slot = [this]() ABSL_SHARED_LOCKS_REQUIRED(mutex_) { return busy_ < workers_; };
    if (!mutex_.AwaitWithDeadline(absl::Condition(&free_slot), call.deadline())) {
      return fail(absl::DeadlineExceededError("no extraction slot before the deadline"));
    }
    ++busy_;
  }
  absl::StatusOr<LocalFeatures> features =
      ExtractLocalFeatures(*mesh, options->extractor, graph ? &*graph : nullptr);
  {
    absl::MutexLock lock(&mutex_);
    --busy_;
  }
  if (!features.ok()) return fail(features.status());
  v1::ExtractResponse response;
  wire::FeaturesToProto(*features, response.mutable_features());
  return response;
}

}  // namespace meshseek
