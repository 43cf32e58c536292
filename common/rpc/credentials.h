// TLS and bearer tokens, in one place for every meshseek server and client.
//
// Every binary takes the same three files, with the same meaning on both
// sides of a connection:
//   --tls_cert / --tls_key  the certificate chain and private key (PEM) this
//                           process presents: a server's always, a client's
//                           for mutual TLS;
//   --tls_ca                the CA bundle (PEM) this process verifies its
//                           peers against: a client verifies the server's
//                           certificate; a server given one requires a client
//                           certificate signed by it (mutual TLS).
// A server with a certificate refuses plaintext connections; without one it
// serves plaintext as before (the embedded stack on loopback does).
//
// A server can also require a bearer token (--token_file): every call must
// carry `authorization: Bearer <token>`, compared in constant time, or fails
// with UNAUTHENTICATED before it reaches a handler or takes a server thread.
// grpc.health.v1 stays open so probes need no secret. The token needs TLS on
// both sides: in plaintext anyone on the path could read and replay it, and
// gRPC itself never sends call credentials over an insecure channel.
//
// Files are read once, when the server or channel is set up; a missing,
// unreadable or empty file is an error that names the file and the flag.
#ifndef MESHSEEK_COMMON_RPC_CREDENTIALS_H_
#define MESHSEEK_COMMON_RPC_CREDENTIALS_H_

#include <grpcpp/security/credentials.h>
#include <grpcpp/security/server_credentials.h>

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace meshseek::rpc {

/// PEM files of one side of a connection (see above). Empty: not given.
struct TlsOptions {
  /// Certificate chain this process presents (--tls_cert).
  std::string cert_file;
  /// Private key of that certificate (--tls_key); given with cert_file or not at all.
  std::string key_file;
  /// CA bundle peers are verified against (--tls_ca).
  std::string ca_file;
};

struct ServerSecurityOptions {
  /// cert_file + key_file turn TLS on; ca_file then also requires and
  /// verifies client certificates (mutual TLS). ca_file alone is an error.
  TlsOptions tls;
  /// File whose content (surrounding whitespace trimmed) is the bearer token
  /// every call except grpc.health.v1 must carry; empty: no token. Needs TLS.
  std::string token_file;

  bool tls_enabled() const { return !tls.cert_file.empty(); }
  /// Pairs and combinations only; the files are read by MakeServerCredentials.
  absl::Status Validate() const;
};

struct ClientSecurityOptions {
  /// Any of the files turns TLS on. ca_file verifies the server (empty: the
  /// system's roots); cert_file + key_file are the client certificate for
  /// servers that require one.
  TlsOptions tls;
  /// File holding the bearer token sent with every call; empty: none. Needs TLS.
  std::string token_file;
  /// Name the server's certificate must carry when it is not the host of the
  /// target (e.g. "ipv4:10.0.0.1:50051,10.0.0.2:50051"); empty: the target's host.
  std::string server_name;

  bool tls_enabled() const {
    return !tls.ca_file.empty() || !tls.cert_file.empty() || !tls.key_file.empty();
  }
  absl::Status Validate() const;
};

/// Insecure credentials when TLS is off; otherwise TLS credentials from the
/// files, with the token check installed when a token file is given.
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const ServerSecurityOptions& options);

/// Insecure credentials when TLS is off; otherwise TLS credentials from the
/// files, composed with the bearer token when a token file is given.
absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> MakeChannelCredentials(
    const ClientSecurityOptions& options);

/// The contents of `path`; `what` names it in errors ("--tls_cert").
/// NotFound / PermissionDenied / InvalidArgument (empty file) name both.
absl::StatusOr<std::string> ReadSecretFile(const std::string& path, const std::string& what);

/// The bearer token in `path` (ReadSecretFile), surrounding whitespace
/// trimmed; InvalidArgument naming `what` and the file when nothing is left or
/// it holds a space or a byte outside printable ASCII.
absl::StatusOr<std::string> ReadTokenFile(const std::string& path, const std::string& what);
/// Compares without an early exit, so the time taken says nothing about how
/// much of a guess was right. Lengths may differ (then false).
bool ConstantTimeEquals(const std::string& a, const std::string& b);

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_CREDENTIALS_H_
