#include "common/rpc/http_server.h"

#include <httplib.h>
#include <sys/socket.h>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"

namespace meshseek::rpc {

absl::StatusOr<int> BindHttpServer(httplib::Server* server,
                                   const std::string& host,
                                   int port,
                                   const std::string& what) {
  server->set_socket_options([](socket_t socket) {
    const int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  int bound = -1;
  if (port == 0) {
    bound = server->bind_to_any_port(host);
  } else if (server->bind_to_port(host, port)) {
    bound = port;
  }
  if (bound <= 0) {
    return absl::UnavailableError(
        absl::StrCat(what, ": cannot listen on ", host, ":", port, " (port in use?)"));
  }
  return bound;
}

std::thread ServeHttpInBackground(httplib::Server* server) {
  std::thread thread([server] { server->listen_after_bind(); });
  // A bound server starts at once; the bound only guards against a listen
  // that fails before it runs.
  const absl::Time give_up = absl::Now() + absl::Seconds(10);
  while (!server->is_running() && absl::Now() < give_up) absl::SleepFor(absl::Milliseconds(1));
  return thread;
}

}  // namespace meshseek::rpc
