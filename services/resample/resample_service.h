// The resample service: mesh -> N_RLD area-uniform Sobol points joined into a
// symmetrised kNN graph (ResampleSurfaceGraph, rld_sift.h). Stateless.
#ifndef MESHSEEK_SERVICES_RESAMPLE_RESAMPLE_SERVICE_H_
#define MESHSEEK_SERVICES_RESAMPLE_RESAMPLE_SERVICE_H_

#include "common/geometry/mesh_io.h"
#include "common/rpc/handler.h"
#include "meshseek/v1/resample.pb.h"

namespace meshseek {

class ResampleService final {
 public:
  /// `mesh_limits` bound a mesh sent as a file (or as arrays).
  explicit ResampleService(const MeshReadOptions& mesh_limits = {}) : mesh_limits_(mesh_limits) {}

  absl::StatusOr<v1::ResampleResponse> Resample(const v1::ResampleRequest& request,
                                                const rpc::CallContext& call);

 private:
  const MeshReadOptions mesh_limits_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_RESAMPLE_RESAMPLE_SERVICE_H_
