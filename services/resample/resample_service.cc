#include "services/resample/resample_service.h"

#include "absl/strings/str_cat.h"
#include "common/features/rld_sift.h"
#include "common/wire/convert.h"
#include "common/base/status_macros.h"

namespace meshseek {

absl::StatusOr<v1::ResampleResponse> ResampleService::Resample(
    const v1::ResampleRequest& request, const rpc::CallContext&) {
  RldSiftOptions limits;  // validates the two parameters as RLD-SIFT does
  limits.num_samples = request.num_samples();
  limits.neighbors = request.neighbors();
  MESHSEEK_RETURN_IF_ERROR(limits.Validate());
  MESHSEEK_ASSIGN_OR_RETURN(const TriangleMesh mesh, wire::MeshFromProto(request.mesh(), mesh_limits_));
  MESHSEEK_ASSIGN_OR_RETURN(
      const PointGraph graph,
      ResampleSurfaceGraph(mesh, request.num_samples(), request.neighbors()));
  v1::ResampleResponse response;
  wire::GraphToProto(graph, response.mutable_graph());
  return response;
}

}  // namespace meshseek
