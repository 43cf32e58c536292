#include "services/resample/resample_service.h"

#include "absl/strings/str_cat.h"
#include "common/features/rld_sift.h"
#include "common/rpc/convert.h"
#include "common/rpc/status.h"

namespace meshseek {

grpc::Status ResampleService::Resample(grpc::ServerContext*,
                                       const v1::ResampleRequest* request,
                                       v1::ResampleResponse* response) {
  RldSiftOptions limits;  // validates the two parameters as RLD-SIFT does
  limits.num_samples = request->num_samples();
  limits.neighbors = request->neighbors();
  if (absl::Status valid = limits.Validate(); !valid.ok()) return rpc::ToGrpcStatus(valid);
  absl::StatusOr<TriangleMesh> mesh = rpc::MeshFromProto(request->mesh(), mesh_limits_);
  if (!mesh.ok()) return rpc::ToGrpcStatus(mesh.status());
  absl::StatusOr<PointGraph> graph =
      ResampleSurfaceGraph(*mesh, request->num_samples(), request->neighbors());
  if (!graph.ok()) return rpc::ToGrpcStatus(graph.status());
  rpc::GraphToProto(*graph, response->mutable_graph());
  return grpc::Status::OK;
}

}  // namespace meshseek
