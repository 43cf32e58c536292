#include "common/rpc/credentials.h"

#include <grpcpp/security/auth_metadata_processor.h>
#include <openssl/crypto.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace meshseek::rpc {
namespace {

constexpr char kHealthPrefix[] = "/grpc.health.v1.Health/";

// OpenSSL 3 frees its global and per-thread state in an atexit handler
// (OPENSSL_cleanup) that assumes every other thread has stopped. gRPC's
// threads may still run when a process leaves main, and one that ends during
// the cleanup frees its thread-local part of that state a second time: a
// double free at exit, seen by ASan in security_test (openssl/openssl#6214,
// grpc/grpc#38539). The operating system reclaims the memory anyway, so the
// handler is never registered. The first OPENSSL_init_crypto call decides,
// and libcpp-httplib makes one in its own library constructor, before any of
// the executable's constructors; so this runs from .preinit_array, which the
// dynamic loader calls before every shared library's initialisers (libcrypto
// is loaded and relocated by then; its initialisation is idempotent).
void KeepOpenSslStateUntilExit() { OPENSSL_init_crypto(OPENSSL_INIT_NO_ATEXIT, nullptr); }
[[gnu::used, gnu::section(".preinit_array")]] void (*const kKeepOpenSslStateUntilExit)() =
    &KeepOpenSslStateUntilExit;

// Checks `authorization: Bearer <token>` on every call but health checks.
// Runs inline in gRPC's transport (not blocking: a comparison), before the
// call is matched to a handler, so refused calls never take a server thread.
class BearerTokenProcessor final : public grpc::AuthMetadataProcessor {
 public:
  explicit BearerTokenProcessor(std::string token) : expected_(absl::StrCat("Bearer ", token)) {}

  bool IsBlocking() const override { return false; }

  grpc::Status Process(const InputMetadata& metadata,
                       grpc::AuthContext* /*context*/,
                       OutputMetadata* consumed,
                       OutputMetadata* /*response*/) override {
    // The transport hands the processor every header, the :path pseudo
    // header included, which is how health checks are told apart.
    auto path = metadata.find(":path");
    if (path != metadata.end() &&
        absl::StartsWith(absl::string_view(path->second.data(), path->second.size()),
                         kHealthPrefix)) {
      return grpc::Status::OK;
    }
    auto header = metadata.find("authorization");
    if (header == metadata.end()) {
      return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                          "this server requires a bearer token (client: --token_file)");
    }
    const std::string given(header->second.data(), header->second.size());
    if (!ConstantTimeEquals(given, expected_)) {
      return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "wrong bearer token");
    }
    // Consumed: handlers never see the secret in their client metadata.
    consumed->insert({"authorization", given});
    return grpc::Status::OK;
  }

 private:
  const std::string expected_;
};

absl::Status CheckPair(const TlsOptions& tls, const char* side) {
  if (tls.cert_file.empty() != tls.key_file.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        side, ": --tls_cert and --tls_key go together (got only ",
        tls.cert_file.empty() ? "--tls_key" : "--tls_cert", ")"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::string> ReadTokenFile(const std::string& path, const std::string& what) {
  // A token is sent as a header value (HTTP/2's or HTTP/1.1's): printable
  // ASCII without spaces keeps it from being mangled or split on the way.
  absl::StatusOr<std::string> token = ReadSecretFile(path, what);
  if (!token.ok()) return token.status();
  std::string trimmed(absl::StripAsciiWhitespace(*token));
  if (trimmed.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(what, " '", path, "' holds only whitespace"));
  }
  for (char c : trimmed) {
    if (c <= 0x20 || c >= 0x7f) {
      return absl::InvalidArgumentError(absl::StrCat(
          what, " '", path, "': the token must be printable ASCII without spaces"));
    }
  }
  return trimmed;
}

bool ConstantTimeEquals(const std::string& a, const std::string& b) {
  // Every byte of the expected value `b` is visited whatever `a` holds; a
  // length difference is folded into the same accumulator.
  volatile unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < b.size(); ++i) {
    const unsigned char x = i < a.size() ? static_cast<unsigned char>(a[i]) : 0;
    diff = diff | static_cast<unsigned char>(x ^ static_cast<unsigned char>(b[i]));
  }
  return diff == 0;
}

absl::StatusOr<std::string> ReadSecretFile(const std::string& path, const std::string& what) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) {
    return absl::InvalidArgumentError(absl::StrCat(what, " '", path, "' is a folder, not a file"));
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    const std::string message = absl::StrCat(what, " '", path, "': cannot read (",
                                             error != 0 ? std::strerror(error) : "cannot open", ")");
    if (error == EACCES) return absl::PermissionDeniedError(message);
    return absl::NotFoundError(message);
  }
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return absl::DataLossError(absl::StrCat(what, " '", path, "': read error"));
  std::string data = contents.str();
  if (data.empty()) return absl::InvalidArgumentError(absl::StrCat(what, " '", path, "' is empty"));
  return data;
}

absl::Status ServerSecurityOptions::Validate() const {
  if (absl::Status pair = CheckPair(tls, "server"); !pair.ok()) return pair;
  if (!tls_enabled() && !tls.ca_file.empty()) {
    return absl::InvalidArgumentError(
        "server: --tls_ca (require client certificates) needs --tls_cert and --tls_key");
  }
  if (!token_file.empty() && !tls_enabled()) {
    return absl::InvalidArgumentError(
        "server: --token_file needs TLS (--tls_cert, --tls_key): a bearer token sent in "
        "plaintext can be read and replayed by anyone on the path");
  }
  return absl::OkStatus();
}

absl::Status ClientSecurityOptions::Validate() const {
  if (absl::Status pair = CheckPair(tls, "client"); !pair.ok()) return pair;
  if (!token_file.empty() && !tls_enabled()) {
    return absl::InvalidArgumentError(
        "client: --token_file needs TLS (--tls_ca): gRPC sends tokens only over TLS");
  }
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const ServerSecurityOptions& options) {
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  if (!options.tls_enabled()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions ssl(
      options.tls.ca_file.empty() ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                                  : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  grpc::SslServerCredentialsOptions::PemKeyCertPair pair;
  absl::StatusOr<std::string> cert = ReadSecretFile(options.tls.cert_file, "--tls_cert");
  if (!cert.ok()) return cert.status();
  absl::StatusOr<std::string> key = ReadSecretFile(options.tls.key_file, "--tls_key");
  if (!key.ok()) return key.status();
  pair.cert_chain = *cert;
  pair.private_key = *key;
  ssl.pem_key_cert_pairs.push_back(pair);
  if (!options.tls.ca_file.empty()) {
    absl::StatusOr<std::string> ca = ReadSecretFile(options.tls.ca_file, "--tls_ca");
    if (!ca.ok()) return ca.status();
    ssl.pem_root_certs = *ca;
  }
  std::shared_ptr<grpc::ServerCredentials> credentials = grpc::SslServerCredentials(ssl);
  if (!options.token_file.empty()) {
    absl::StatusOr<std::string> token = ReadTokenFile(options.token_file, "--token_file");
    if (!token.ok()) return token.status();
    credentials->SetAuthMetadataProcessor(std::make_shared<BearerTokenProcessor>(*token));
  }
  return credentials;
}

absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> MakeChannelCredentials(
    const ClientSecurityOptions& options) {
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  if (!options.tls_enabled()) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions ssl;
  if (!options.tls.ca_file.empty()) {
    absl::StatusOr<std::string> ca = ReadSecretFile(options.tls.ca_file, "--tls_ca");
    if (!ca.ok()) return ca.status();
    ssl.pem_root_certs = *ca;
  }
  if (!options.tls.cert_file.empty()) {
    absl::StatusOr<std::string> cert = ReadSecretFile(options.tls.cert_file, "--tls_cert");
    if (!cert.ok()) return cert.status();
    absl::StatusOr<std::string> key = ReadSecretFile(options.tls.key_file, "--tls_key");
    if (!key.ok()) return key.status();
    ssl.pem_cert_chain = *cert;
    ssl.pem_private_key = *key;
  }
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::SslCredentials(ssl);
  if (!options.token_file.empty()) {
    absl::StatusOr<std::string> token = ReadTokenFile(options.token_file, "--token_file");
    if (!token.ok()) return token.status();
    credentials = grpc::CompositeChannelCredentials(credentials, grpc::AccessTokenCredentials(*token));
  }
  return credentials;
}

}  // namespace meshseek::rpc
