// meshseek web: the query page and its JSON API in front of a coordinator
// (web_gateway.h), until SIGTERM or Ctrl-C.
#include <cstdio>

#include "cli/commands.h"
#include "cli/coordinator_client.h"
#include "cli/web_gateway.h"
#include "common/base/status_macros.h"
#include "common/rpc/server.h"

namespace meshseek::cli {

absl::Status RunWeb(const CliFlags& flags) {
  rpc::BlockTerminationSignals();
  WebGatewayOptions options = flags.web;
  options.port = flags.PortOr(8080);
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_ASSIGN_OR_RETURN(auto client, CoordinatorClient::Open(flags.client));
  options.retry = client->retry();
  MESHSEEK_ASSIGN_OR_RETURN(auto gateway, WebGateway::Start(client->stub(), options));
  std::printf("meshseek web: %s://%s:%d/%s ; Ctrl-C stops\n",
              options.tls.cert_file.empty() ? "http" : "https",
              options.host == "0.0.0.0" ? "localhost" : options.host.c_str(), gateway->port(),
              options.token_file.empty() ? "" : " (API calls need the bearer token)");
  std::fflush(stdout);
  rpc::WaitForTerminationSignal();
  gateway->Stop();
  return absl::OkStatus();
}

}  // namespace meshseek::cli
