// Binding a cpp-httplib server (the web gateway, the metrics endpoint) the
// way the gRPC servers bind: SO_REUSEADDR only. httplib's default also sets
// SO_REUSEPORT, which lets a second server bind a port in use and silently
// share its connections instead of failing.
#ifndef MESHSEEK_COMMON_RPC_HTTP_SERVER_H_
#define MESHSEEK_COMMON_RPC_HTTP_SERVER_H_

#include <string>
#include <thread>

#include "absl/status/statusor.h"

namespace httplib {
class Server;
}

namespace meshseek::rpc {

/// Binds `server` to host:port (port 0: any free port) and returns the bound
/// port; Unavailable, naming `what` and the address, when it is taken.
absl::StatusOr<int> BindHttpServer(httplib::Server* server,
                                   const std::string& host,
                                   int port,
                                   const std::string& what);

/// Serves the bound `server` on a thread of its own (join it after
/// server->stop()) and returns once it takes connections: a stop() sooner
/// would be lost, and the thread would serve on for ever.
std::thread ServeHttpInBackground(httplib::Server* server);

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_HTTP_SERVER_H_
