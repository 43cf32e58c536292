// The web gateway: an HTTP server (cpp-httplib) in front of a coordinator,
// serving the query page (web/, built into the binary, so it works offline
// and in a container without files beside it) and a small JSON API the page
// calls, each call one gRPC call to the coordinator:
//
//   GET  /api/collections                   ListCollections
//   POST /api/query   (multipart: collection, top_k, mesh = the file)
//                                           Query with the file's bytes
//   GET  /api/query?collection=C&model_id=M&top_k=K
//                                           Query with a model of C
//   POST /api/query_image (multipart: collection, top_k, image = a PNG or JPEG)
//                                           QueryByImage with the picture's bytes
//   GET  /api/thumbnail?collection=C&model_id=M   GetThumbnail (image/png)
//
// Who reaches it (docs/operations.md, "The query page"): it listens on
// loopback unless told otherwise. Exposed on another address, it wants TLS
// (its own certificate and key) and a bearer token that every /api call
// must carry as `Authorization: Bearer <token>` (401 otherwise, compared in
// constant time; the page and its assets stay open so that a browser can ask
// for the token), or an explicit `open` for a private network or an
// authenticating proxy in front. The coordinator's own TLS and token are the
// client's (CoordinatorClient), not these.
//
// A query answers {"query": {...}, "results": [{"model_id", "label",
// "distance", "rank"}]}; an uploaded file's query carries its own thumbnail
// (drawn here, as a data: URI) and a one-line summary of what was read.
// Errors answer {"error": "..."} with the HTTP status of the gRPC code
// (INVALID_ARGUMENT 400, NOT_FOUND 404, FAILED_PRECONDITION 409,
// RESOURCE_EXHAUSTED 413, UNAVAILABLE 503, others 500) and the
// coordinator's message, which names what is wrong.
#ifndef MESHSEEK_CLI_WEB_GATEWAY_H_
#define MESHSEEK_CLI_WEB_GATEWAY_H_

#include <cstddef>
#include <memory>
#include <string>
#include <thread>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/rpc/client.h"
#include "common/rpc/credentials.h"
#include "meshseek/v1/coordinator.grpc.pb.h"

namespace httplib {
class Server;
}

namespace meshseek::cli {

struct WebGatewayOptions {
  /// Address to listen on: loopback, so that only this machine reaches the
  /// page. Any other ("0.0.0.0": every interface, as in a container) needs
  /// TLS and token_file, or `open`.
  std::string host = "127.0.0.1";
  /// HTTPS: the certificate chain and private key (PEM) the gateway presents
  /// (--web_tls_cert, --web_tls_key); both or neither. ca_file is not used.
  rpc::TlsOptions tls;
  /// File holding the bearer token every /api call must carry (printable
  /// ASCII, surrounding whitespace trimmed; --web_token_file). Empty: none.
  std::string token_file;
  /// Serve a non-loopback host without TLS and a token (--web_open): only on
  /// a private network or behind a proxy that authenticates.
  bool open = false;
  /// Port to listen on, 0 for any free one (see WebGateway::port).
  int port = 8080;
  /// Largest request body (an uploaded mesh file), in bytes, 1 KiB..1 GiB.
  std::size_t max_upload_bytes = 64 << 20;
  /// Results a page may ask for per query, 1..1000.
  int max_top_k = 200;
  /// Deadline of each call to the coordinator (a query of a large fused
  /// collection takes seconds).
  absl::Duration call_deadline = absl::Seconds(120);
  /// Retries of each call while the coordinator is unreachable
  /// (CoordinatorClient::retry(): --reconnect_for).
  rpc::RetryOptions retry;

  absl::Status Validate() const;
};

/// Whether `host` names this machine only (localhost, 127.0.0.0/8, ::1).
bool IsLoopback(const std::string& host);

class WebGateway {
 public:
  /// Binds the port and starts serving on a thread of its own; Unavailable
  /// when the port cannot be bound. `coordinator` is not owned and must
  /// outlive the gateway.
  static absl::StatusOr<std::unique_ptr<WebGateway>> Start(v1::Coordinator::Stub* coordinator,
                                                           const WebGatewayOptions& options);
  ~WebGateway();

  /// The bound port.
  int port() const { return port_; }
  /// Stops taking connections and waits for the server thread; idempotent.
  void Stop();

 private:
  WebGateway() = default;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
};

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_WEB_GATEWAY_H_
