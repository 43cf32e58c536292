#include "cli/session.h"

#include <string>

#include "absl/flags/declare.h"
#include "absl/flags/flag.h"
#include "common/base/status_macros.h"
#include "common/rpc/mesh_limit_flags.h"

ABSL_FLAG(std::string,
          server,
          "",
          "coordinator address host:port; empty: start the embedded stack on --data_dir; "
          "'in-process': eval without services (the benchmark reference)");
ABSL_FLAG(std::string, data_dir, "meshseek-data", "state folder of the embedded stack");
ABSL_FLAG(std::string,
          tls_ca,
          "",
          "PEM CA bundle the coordinator (--server) is verified against: turns TLS on; "
          "serve: require client certificates signed by it");
ABSL_FLAG(std::string,
          tls_cert,
          "",
          "PEM certificate this process presents: the client's for mutual TLS, or serve's");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(std::string,
          tls_server_name,
          "",
          "name the coordinator's certificate carries, when not the host of --server");
ABSL_FLAG(std::string,
          token_file,
          "",
          "file holding the coordinator's bearer token: sent with every call to --server; "
          "serve: required of every caller");
ABSL_FLAG(absl::Duration,
          reconnect_for,
          absl::Minutes(2),
          "how long the client keeps reconnecting to a coordinator that went away");

ABSL_FLAG(int,
          port,
          -1,
          "serve: coordinator port of the embedded stack (default 50051; 0: any free port); "
          "web: port of the page (default 8080)");
// Defined in pipeline_flags.cc.
ABSL_DECLARE_FLAG(int, threads);

namespace meshseek::cli {

absl::StatusOr<std::unique_ptr<Session>> Session::Open() {
  auto session = std::make_unique<Session>();
  std::string address = absl::GetFlag(FLAGS_server);
  if (address.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(const MeshReadOptions limits, rpc::MeshLimitsFromFlags());
    MESHSEEK_ASSIGN_OR_RETURN(
        session->stack_,
        EmbeddedStack::Start(
            absl::GetFlag(FLAGS_data_dir), absl::GetFlag(FLAGS_threads), 0, {}, limits));
    address = session->stack_->coordinator_address();
  }
  rpc::ChannelOptions channel;
  channel.retry_service = "";  // the client retries itself, knowing what is idempotent
  if (session->stack_ == nullptr) {
    // TLS and token only towards a --server: the command's own stack
    // listens on loopback in plaintext.
    rpc::ClientSecurityOptions security;
    security.tls.ca_file = absl::GetFlag(FLAGS_tls_ca);
    security.tls.cert_file = absl::GetFlag(FLAGS_tls_cert);
    security.tls.key_file = absl::GetFlag(FLAGS_tls_key);
    security.server_name = absl::GetFlag(FLAGS_tls_server_name);
    security.token_file = absl::GetFlag(FLAGS_token_file);
    MESHSEEK_ASSIGN_OR_RETURN(channel, rpc::WithClientSecurity(security, channel));
  }
  session->stub_ = v1::Coordinator::NewStub(rpc::MakeChannel(address, channel));
  return session;
}

int PortOr(int fallback) {
  const int port = absl::GetFlag(FLAGS_port);
  return port < 0 ? fallback : port;
}

rpc::RetryOptions ReconnectRetry() {
  rpc::RetryOptions retry;
  retry.attempts = 1 + static_cast<int>(absl::GetFlag(FLAGS_reconnect_for) / absl::Seconds(2));
  retry.max_backoff = absl::Seconds(2);
  return retry;
}

}  // namespace meshseek::cli
