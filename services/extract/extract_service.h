// The extract service: mesh (+ resampled graph for RLD-SIFT) -> local
// features by the requested method (ExtractLocalFeatures). Stateless; the hot
// path, scaled by replicas.
//
// At most `workers` extractions run at once (each is CPU-bound and on one
// thread unless it asks for more: ExtractRequest.threads, at most `workers`,
// what a query does so that a fused collection's methods finish together);
// further calls wait for a slot, and a call whose deadline passes while
// waiting fails DEADLINE_EXCEEDED without having started.
#ifndef MESHSEEK_SERVICES_EXTRACT_EXTRACT_SERVICE_H_
#define MESHSEEK_SERVICES_EXTRACT_EXTRACT_SERVICE_H_

#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "common/geometry/mesh_io.h"
#include "common/rpc/handler.h"
#include "meshseek/v1/extract.pb.h"

namespace meshseek {

struct ExtractServiceOptions {
  /// Concurrent extractions; <= 0: one per core.
  int workers = 0;
  /// Bounds of a mesh sent as a file (or as arrays).
  MeshReadOptions mesh_limits;

  absl::Status Validate() const;
};

class ExtractService final {
 public:
  explicit ExtractService(const ExtractServiceOptions& options);

  absl::StatusOr<v1::ExtractResponse> Extract(const v1::ExtractRequest& request,
                                              const rpc::CallContext& call);

 private:
  const int workers_;
  const MeshReadOptions mesh_limits_;
  absl::Mutex mutex_;
  int busy_ ABSL_GUARDED_BY(mutex_) = 0;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_EXTRACT_EXTRACT_SERVICE_H_
