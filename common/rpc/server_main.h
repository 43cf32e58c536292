// The part of every service's main that is the same for all: server flags
// (--host, --port, --max_message_mb, --server_threads, --max_queued_calls,
// --grace_period, --max_connection_age, --tls_cert, --tls_key, --tls_ca,
// --health_port, --metrics_port), serving until SIGTERM/SIGINT, graceful shutdown.
//
//   int main(int argc, char** argv) {
//     meshseek::rpc::BlockTerminationSignals();
//     absl::ParseCommandLine(argc, argv);
//     ... validated service options from the service's own flags ...
//     return meshseek::rpc::ServeUntilSignal("extract", {&service});
//   }
#ifndef MESHSEEK_COMMON_RPC_SERVER_MAIN_H_
#define MESHSEEK_COMMON_RPC_SERVER_MAIN_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/rpc/server.h"

namespace meshseek::rpc {

// ServerOptions from the server flags, validated.
absl::StatusOr<ServerOptions> ServerOptionsFromFlags();

// Starts the server with the flags' options, waits for SIGTERM or SIGINT,
// shuts down gracefully, then calls `on_stop` (e.g. stop background work). Returns
// the process exit code; errors are printed.
int ServeUntilSignal(const std::string& name,
                     const std::vector<grpc::Service*>& services,
                     const std::function<void()>& on_stop = nullptr);

// The same with options the caller completed (the coordinator adds its
// bearer token to ServerOptionsFromFlags()).
int ServeUntilSignal(const std::string& name,
                     const std::vector<grpc::Service*>& services,
                     const ServerOptions& options,
                     const std::function<void()>& on_stop = nullptr);

// Prints "<name>: <status>" to stderr and returns 2 (bad flags).
int ExitWithError(const std::string& name, const absl::Status& status);

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_SERVER_MAIN_H_
