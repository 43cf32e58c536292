#include "common/rpc/client.h"

#include <algorithm>
#include <thread>

#include "absl/strings/str_cat.h"
#include "common/rpc/status.h"

namespace meshseek::rpc {

std::shared_ptr<grpc::Channel> MakeChannel(const std::string& target,
                                           const ChannelOptions& options) {
  std::string config = R"({"loadBalancingConfig":[{"round_robin":{}}],)"
                       R"("healthCheckConfig":{"serviceName":""})";
  if (!options.retry_service.empty()) {
    absl::StrAppend(&config,
                    R"(,"methodConfig":[{"name":[{"service":")",
                    options.retry_service,
                    R"("}],"retryPolicy":{"maxAttempts":)",
                    std::clamp(options.max_attempts, 2, 5),
                    R"(,"initialBackoff":"0.1s","maxBackoff":"1s","backoffMultiplier":2,)"
                    R"("retryableStatusCodes":["UNAVAILABLE"]}}])");
  }
  config += "}";
  grpc::ChannelArguments args;
  args.SetServiceConfigJSON(config);
  args.SetMaxReceiveMessageSize(options.max_message_bytes);
  args.SetMaxSendMessageSize(options.max_message_bytes);
  // Re-resolve DNS names at most every 5 s (gRPC's default is 30 s), so a
  // scaled-up worker set is seen soon after connections recycle.
  args.SetInt(GRPC_ARG_DNS_MIN_TIME_BETWEEN_RESOLUTIONS_MS, 5000);
  // Reconnect quickly to a replica that comes back.
  args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 100);
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 2000);
  if (options.own_connection) args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  if (!options.tls_server_name.empty()) {
    args.SetSslTargetNameOverride(options.tls_server_name);
  }
  return grpc::CreateCustomChannel(
      target,
      options.credentials != nullptr ? options.credentials : grpc::InsecureChannelCredentials(),
      args);
}

absl::StatusOr<ChannelOptions> WithClientSecurity(const ClientSecurityOptions& security,
                                                  ChannelOptions base) {
  absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> credentials =
      MakeChannelCredentials(security);
  if (!credentials.ok()) return credentials.status();
  base.credentials = *credentials;
  base.tls_server_name = security.server_name;
  return base;
}

void SetDeadline(grpc::ClientContext* context, absl::Duration timeout) {
  context->set_deadline(std::chrono::system_clock::now() + absl::ToChronoMilliseconds(timeout));
}

absl::Status RetryTransient(const std::function<absl::Status()>& call,
                            const RetryOptions& options,
                            const std::atomic<bool>* stop) {
  absl::Duration backoff = options.initial_backoff;
  absl::Status status;
  for (int attempt = 1;; ++attempt) {
    status = call();
    if (status.ok() || !IsTransient(status) || attempt >= options.attempts) return status;
    if (stop != nullptr && stop->load()) return status;
    std::this_thread::sleep_for(absl::ToChronoMilliseconds(backoff));
    backoff = std::min(backoff * 2, options.max_backoff);
  }
}

}  // namespace meshseek::rpc
