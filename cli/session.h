// The coordinator a client command talks to: --server HOST:PORT (with TLS
// and a bearer token when the flags give them), or an embedded stack of
// every service started on --data_dir for the command's duration. Used by
// the gRPC client commands (client_commands.cc) and the web gateway.
#ifndef MESHSEEK_CLI_SESSION_H_
#define MESHSEEK_CLI_SESSION_H_

#include <memory>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cli/embedded_stack.h"
#include "common/rpc/client.h"
#include "meshseek/v1/coordinator.grpc.pb.h"

namespace meshseek::cli {

class Session {
 public:
  /// Connects to --server, or starts the embedded stack when it is empty.
  static absl::StatusOr<std::unique_ptr<Session>> Open();
  v1::Coordinator::Stub* stub() { return stub_.get(); }

 private:
  std::unique_ptr<EmbeddedStack> stack_;
  std::unique_ptr<v1::Coordinator::Stub> stub_;
};

/// --port, or `fallback` when it is not given (serve and web listen on
/// different ports by default).
int PortOr(int fallback);

/// Retries while the coordinator is unreachable, for --reconnect_for.
rpc::RetryOptions ReconnectRetry();

/// A unary call with a deadline, retried while the coordinator is
/// unreachable (only for idempotent calls).
template <typename Request, typename Response, typename Method>
absl::Status Call(v1::Coordinator::Stub* stub,
                  Method method,
                  const Request& request,
                  Response* response,
                  absl::Duration deadline = absl::Minutes(1)) {
  return rpc::CallWithRetry(stub, method, request, response, deadline, ReconnectRetry());
}

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_SESSION_H_
