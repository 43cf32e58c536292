// Client side of every meshseek call: channels and retries set up one way.
//
// A channel target is any gRPC target: "host:port" or "dns:///extract:50051"
// (every address the name resolves to, re-resolved when connections close,
// which the servers' max connection age makes happen), or
// "ipv4:127.0.0.1:7001,127.0.0.1:7002" (a fixed list, as the tests use).
// Calls are spread over all addresses by round_robin, and the client's
// health checking (grpc.health.v1) skips replicas that say NOT_SERVING.
// TLS, client certificates and bearer tokens come from credentials.h
// (WithClientSecurity below).
#ifndef MESHSEEK_COMMON_RPC_CLIENT_H_
#define MESHSEEK_COMMON_RPC_CLIENT_H_

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/rpc/credentials.h"

namespace meshseek::rpc {

struct ChannelOptions {
  /// Largest message sent or received.
  int max_message_bytes = 64 << 20;
  /// Fully qualified service (e.g. "meshseek.v1.Extract") whose calls gRPC
  /// itself retries on UNAVAILABLE, on another replica when there is one.
  /// Only for services whose every method is idempotent; empty: none.
  std::string retry_service;
  /// Attempts of such a retry, 2-5.
  int max_attempts = 4;
  /// Channel credentials (MakeChannelCredentials); null: plaintext.
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  /// Name the server's certificate must carry when it is not the target's
  /// host (ClientSecurityOptions::server_name); empty: the target's host.
  std::string tls_server_name;
  /// A connection of this channel's own instead of one shared with every
  /// channel to the same target (load generators acting as many clients).
  bool own_connection = false;
};

// `base` with the credentials and server name of `security` (files read now;
// errors name the file and its flag).
absl::StatusOr<ChannelOptions> WithClientSecurity(const ClientSecurityOptions& security,
                                                  ChannelOptions base = {});

std::shared_ptr<grpc::Channel> MakeChannel(const std::string& target,
                                           const ChannelOptions& options = {});

// Sets a deadline `timeout` from now on `context`. Every call gets one.
void SetDeadline(grpc::ClientContext* context, absl::Duration timeout);

struct RetryOptions {
  /// Tries in all.
  int attempts = 8;
  /// First pause, doubled after each failure up to max_backoff.
  absl::Duration initial_backoff = absl::Milliseconds(100);
  absl::Duration max_backoff = absl::Seconds(5);
};

// Runs `call` until it succeeds, fails with a code that is not transient
// (IsTransient), or has been tried `options.attempts` times; returns the last
// status. Only for idempotent calls. Stops early when `stop` becomes true.
absl::Status RetryTransient(const std::function<absl::Status()>& call,
                            const RetryOptions& options = {},
                            const std::atomic<bool>* stop = nullptr);

// One unary call as every meshseek client makes it: a fresh context with a
// deadline `timeout` per try, retried by RetryTransient. `method` is a
// generated stub's blocking method, e.g. &v1::Extract::Stub::Extract.
template <typename Stub, typename Request, typename Response>
absl::Status CallWithRetry(Stub* stub,
                           grpc::Status (Stub::*method)(grpc::ClientContext*,
                                                        const Request&,
                                                        Response*),
                           const Request& request,
                           Response* response,
                           absl::Duration timeout,
                           const RetryOptions& retry = {},
                           const std::atomic<bool>* stop = nullptr) {
  return RetryTransient(
      [&] {
        grpc::ClientContext context;
        SetDeadline(&context, timeout);
        const grpc::Status status = (stub->*method)(&context, request, response);
        return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                            status.error_message());
      },
      retry,
      stop);
}

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_CLIENT_H_
