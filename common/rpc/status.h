// absl::Status <-> grpc::Status at the RPC edge. Both use the canonical codes,
// so the code and message pass through unchanged in both directions.
#ifndef MESHSEEK_COMMON_RPC_STATUS_H_
#define MESHSEEK_COMMON_RPC_STATUS_H_

#include <grpcpp/support/status.h>

#include "absl/status/status.h"

namespace meshseek::rpc {

grpc::Status ToGrpcStatus(const absl::Status& status);
absl::Status FromGrpcStatus(const grpc::Status& status);

// Codes after which the same call may succeed on another try or another
// replica: UNAVAILABLE, DEADLINE_EXCEEDED, RESOURCE_EXHAUSTED, ABORTED,
// CANCELLED (a server shutting down cancels its calls).
bool IsTransient(const absl::Status& status);

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_STATUS_H_
