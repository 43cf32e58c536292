// meshseek web: the query page and its JSON API in front of a coordinator
// (web_gateway.h), until SIGTERM or Ctrl-C.
#include <cstdio>

#include "absl/flags/declare.h"
#include "absl/flags/flag.h"
#include "cli/commands.h"
#include "cli/session.h"
#include "cli/web_gateway.h"
#include "common/base/status_macros.h"
#include "common/rpc/server.h"

ABSL_FLAG(std::string, web_host, "0.0.0.0", "web: address the page is served on");
ABSL_FLAG(int, web_upload_mb, 64, "web: largest mesh file a browser may upload, in MiB");

namespace meshseek::cli {

absl::Status RunWeb() {
  rpc::BlockTerminationSignals();
  WebGatewayOptions options;
  options.host = absl::GetFlag(FLAGS_web_host);
  options.port = PortOr(8080);
  options.max_upload_bytes = static_cast<std::size_t>(absl::GetFlag(FLAGS_web_upload_mb)) << 20;
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_ASSIGN_OR_RETURN(auto session, Session::Open());
  MESHSEEK_ASSIGN_OR_RETURN(auto gateway, WebGateway::Start(session->stub(), options));
  std::printf("meshseek web: http://%s:%d/ ; Ctrl-C stops\n",
              options.host == "0.0.0.0" ? "localhost" : options.host.c_str(),
              gateway->port());
  std::fflush(stdout);
  rpc::WaitForTerminationSignal();
  gateway->Stop();
  return absl::OkStatus();
}

}  // namespace meshseek::cli
