#include "services/extract/extract_service.h"

#include <algorithm>
#include <optional>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "common/features/local_feature_extractor.h"
#include "common/rpc/convert.h"
#include "common/rpc/status.h"

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

grpc::Status ExtractService::Extract(grpc::ServerContext* context,
                                     const v1::ExtractRequest* request,
                                     v1::ExtractResponse* response) {
  const std::string where =
      request->model_id().empty() ? "" : absl::StrCat("model ", request->model_id(), ": ");
  auto fail = [&](const absl::Status& status) {
    return rpc::ToGrpcStatus(absl::Status(status.code(), absl::StrCat(where, status.message())));
  };
  // Parse and check everything before taking a slot.
  absl::StatusOr<RetrievalPipelineOptions> options =
      rpc::PipelineOptionsFromParams(request->params());
  if (!options.ok()) return fail(options.status());
  absl::StatusOr<TriangleMesh> mesh = rpc::MeshFromProto(request->mesh(), mesh_limits_);
  if (!mesh.ok()) return fail(mesh.status());
  std::optional<PointGraph> graph;
  if (request->has_resampled() && options->extractor.method == FeatureMethod::kRldSift) {
    absl::StatusOr<PointGraph> parsed = rpc::GraphFromProto(request->resampled());
    if (!parsed.ok()) return fail(parsed.status());
    graph = *std::move(parsed);
  }
  {
    absl::MutexLock lock(&mutex_);
    const absl::Time deadline = absl::FromChrono(context->deadline());
    auto free_slot = [this]() ABSL_SHARED_LOCKS_REQUIRED(mutex_) { return busy_ < workers_; };
    if (!mutex_.AwaitWithDeadline(absl::Condition(&free_slot), deadline)) {
      return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                          absl::StrCat(where, "no extraction slot before the deadline"));
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
  rpc::FeaturesToProto(*features, response->mutable_features());
  return grpc::Status::OK;
}

}  // namespace meshseek
