#include "cli/web_gateway.h"

#include <httplib.h>

#include <algorithm>
#include <filesystem>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "common/rpc/client.h"
#include "cli/web_assets.h"
#include "common/base/base64.h"
#include "common/base/json.h"
#include "common/base/status_macros.h"
#include "common/geometry/mesh_io.h"
#include "common/global/picture_silhouette.h"
#include "common/render/thumbnail.h"
#include "common/rpc/http_server.h"

namespace meshseek::cli {
namespace {

int HttpStatusOf(absl::StatusCode code) {
  switch (code) {
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kOutOfRange:
      return 400;
    case absl::StatusCode::kUnauthenticated:
      return 401;
    case absl::StatusCode::kPermissionDenied:
      return 403;
    case absl::StatusCode::kNotFound:
      return 404;
    case absl::StatusCode::kAlreadyExists:
    case absl::StatusCode::kFailedPrecondition:
      return 409;
    case absl::StatusCode::kResourceExhausted:
      return 413;
    case absl::StatusCode::kUnavailable:
      return 503;
    case absl::StatusCode::kDeadlineExceeded:
      return 504;
    default:
      return 500;
  }
}

void ReplyJson(httplib::Response& response, const Json& body, int status = 200) {
  response.status = status;
  response.set_header("Cache-Control", "no-store");
  response.set_content(body.Dump(0), "application/json");
}

void ReplyError(httplib::Response& response, const absl::Status& status) {
  Json body = Json::MakeObject();
  body.Set("error", std::string(status.message()));
  ReplyJson(response, body, HttpStatusOf(status.code()));
}

// The request parameter `name` (query string or multipart field).
std::string Param(const httplib::Request& request, const std::string& name) {
  if (request.has_param(name)) return request.get_param_value(name);
  if (request.has_file(name)) return request.get_file_value(name).content;
  return "";
}

absl::StatusOr<int> TopK(const httplib::Request& request, int max_top_k) {
  const std::string text = Param(request, "top_k");
  int top_k = 24;
  if (!text.empty() && (!absl::SimpleAtoi(text, &top_k) || top_k < 1 || top_k > max_top_k)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "top_k must be a whole number from 1 to ", max_top_k, ", got '", text.substr(0, 32), "'"));
  }
  return top_k;
}

std::string MethodOf(const v1::Collection& collection) {
  for (const v1::ParamValue& v : collection.params().values()) {
    if (v.name() == "method") return v.value();
  }
  return "";
}

Json ResultsJson(const v1::QueryResponse& answer) {
  Json results = Json::MakeArray();
  int rank = 0;
  for (const v1::ScoredModel& m : answer.results()) {
    Json r = Json::MakeObject();
    r.Set("rank", ++rank);
    r.Set("model_id", m.model_id());
    r.Set("label", m.label());
    r.Set("distance", static_cast<double>(m.distance()));  // +inf (no features): null
    results.Push(std::move(r));
  }
  return results;
}

// HTTPS with the certificate and key when given, plain HTTP otherwise. The
// files are read here first so that a missing one is named.
absl::StatusOr<std::unique_ptr<httplib::Server>> MakeServer(const rpc::TlsOptions& tls) {
  if (tls.cert_file.empty()) return std::make_unique<httplib::Server>();
  MESHSEEK_RETURN_IF_ERROR(rpc::ReadSecretFile(tls.cert_file, "--web_tls_cert").status());
  MESHSEEK_RETURN_IF_ERROR(rpc::ReadSecretFile(tls.key_file, "--web_tls_key").status());
  auto server = std::make_unique<httplib::SSLServer>(tls.cert_file.c_str(), tls.key_file.c_str());
  if (!server->is_valid()) {
    return absl::InvalidArgumentError(absl::StrCat("web: --web_tls_cert '", tls.cert_file,
                                                   "' and --web_tls_key '", tls.key_file,
                                                   "' are not a PEM certificate and its key"));
  }
  return server;
}

// A multipart file of a request: its own name (no folders) and its bytes.
struct UploadedFile {
  std::string name;
  std::string content;
};

// The file `field` (httplib hands out a copy); InvalidArgument when it is
// missing or empty.
absl::StatusOr<UploadedFile> Upload(const httplib::Request& request, const std::string& field) {
  if (!request.has_file(field)) {
    return absl::InvalidArgumentError(absl::StrCat("no ", field, " file in the request"));
  }
  httplib::MultipartFormData file = request.get_file_value(field);
  UploadedFile upload{std::filesystem::path(file.filename).filename().string(),
                      std::move(file.content)};
  if (upload.content.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(upload.name, ": empty file"));
  }
  return upload;
}

class Handlers {
 public:
  Handlers(v1::Coordinator::Stub* coordinator, const WebGatewayOptions& options)
      : coordinator_(coordinator), options_(options) {}

  void Collections(const httplib::Request&, httplib::Response& response) const {
    v1::ListCollectionsResponse answer;
    if (absl::Status s =
            Ask(&v1::Coordinator::Stub::ListCollections, v1::ListCollectionsRequest(), &answer);
        !s.ok()) {
      return ReplyError(response, s);
    }
    Json list = Json::MakeArray();
    for (const v1::Collection& c : answer.collections()) {
      Json entry = Json::MakeObject();
      entry.Set("name", c.name());
      entry.Set("method", MethodOf(c));
      entry.Set("models", c.models());
      entry.Set("indexed", c.indexed());
      entry.Set("pending", c.pending());
      entry.Set("failed", c.failed());
      entry.Set("built", !c.codebook_id().empty());
      list.Push(std::move(entry));
    }
    Json body = Json::MakeObject();
    body.Set("collections", std::move(list));
    ReplyJson(response, body);
  }

  // An uploaded file: read here (for its thumbnail, and so that a bad file
  // is refused with the reader's message before the coordinator is asked),
  // then sent as the file's bytes, which the coordinator reads again with
  // its own limits.
  void QueryWithFile(const httplib::Request& request, httplib::Response& response) const {
    absl::StatusOr<UploadedFile> upload = Upload(request, "mesh");
    if (!upload.ok()) return ReplyError(response, upload.status());
    const std::string& name = upload->name;
    const std::string& content = upload->content;
    absl::StatusOr<MeshFormat> declared = MeshFormatFromPath(name);
    MeshReadReport report;
    absl::StatusOr<TriangleMesh> mesh =
        ParseMesh(content,
                  name,
                  declared.ok() ? std::optional<MeshFormat>(*declared) : std::nullopt,
                  MeshReadOptions(),
                  &report);
    if (!mesh.ok()) return ReplyError(response, mesh.status());
    v1::QueryRequest query;
    query.set_collection(Param(request, "collection"));
    v1::MeshFile* sent = query.mutable_mesh()->mutable_file();
    sent->set_data(content);
    sent->set_name(name);
    Json about = Json::MakeObject();
    about.Set("name", name);
    about.Set("summary", report.Summary());
    if (absl::StatusOr<std::string> png = RenderThumbnailPng(*mesh); png.ok()) {
      about.Set("thumbnail", absl::StrCat("data:image/png;base64,", Base64Encode(*png)));
    }
    RunQuery(request, &v1::Coordinator::Stub::Query, &query, std::move(about), response);
  }

  // A picture: sent on as its bytes; the coordinator decodes it (with the
  // limits of DecodePicture) and names what is wrong with it.
  void QueryWithImage(const httplib::Request& request, httplib::Response& response) const {
    absl::StatusOr<UploadedFile> upload = Upload(request, "image");
    if (!upload.ok()) return ReplyError(response, upload.status());
    const std::string& name = upload->name;
    const std::string& content = upload->content;
    if (content.size() > kMaxPictureFileBytes) {
      return ReplyError(response, absl::ResourceExhaustedError(absl::StrCat(
                                      name, ": a picture may hold at most ", kMaxPictureFileBytes,
                                      " bytes, this one holds ", content.size())));
    }
    v1::QueryByImageRequest query;
    query.set_collection(Param(request, "collection"));
    query.set_image(content);
    Json about = Json::MakeObject();
    about.Set("name", name);
    about.Set("summary", absl::StrCat("a picture of ", content.size() / 1024 + 1,
                                      " KB, matched by its silhouette"));
    RunQuery(request, &v1::Coordinator::Stub::QueryByImage, &query, std::move(about), response);
  }

  void QueryWithModel(const httplib::Request& request, httplib::Response& response) const {
    v1::QueryRequest query;
    query.set_collection(Param(request, "collection"));
    query.set_model_id(Param(request, "model_id"));
    if (query.model_id().empty()) {
      return ReplyError(response, absl::InvalidArgumentError("model_id is missing"));
    }
    Json about = Json::MakeObject();
    about.Set("name", query.model_id());
    about.Set("model_id", query.model_id());
    RunQuery(request, &v1::Coordinator::Stub::Query, &query, std::move(about), response);
  }

  void Thumbnail(const httplib::Request& request, httplib::Response& response) const {
    v1::GetThumbnailRequest ask;
    ask.set_collection(Param(request, "collection"));
    ask.set_model_id(Param(request, "model_id"));
    v1::Thumbnail answer;
    if (absl::Status s = Ask(&v1::Coordinator::Stub::GetThumbnail, ask, &answer); !s.ok()) {
      return ReplyError(response, s);
    }
    // A model id names one mesh until it is removed: a minute of caching
    // spares repeated pages without showing a replaced model for long.
    response.set_header("Cache-Control", "private, max-age=60");
    response.set_content(answer.png(), "image/png");
  }

  void Asset(const httplib::Request& request, httplib::Response& response) const {
    const WebAsset* asset = FindWebAsset(request.path == "/" ? "/index.html" : request.path);
    if (asset == nullptr) {
      response.status = 404;
      response.set_content("not found", "text/plain");
      return;
    }
    response.set_header("Cache-Control", "no-cache");
    response.set_content(asset->content.data(), asset->content.size(), asset->media_type);
  }

 private:
  template <typename Request, typename Answer, typename Method>
  absl::Status Ask(Method method, const Request& request, Answer* answer) const {
    return rpc::CallWithRetry(coordinator_, method, request, answer, options_.call_deadline,
                              options_.retry);
  }

  // Query or QueryByImage with the page's collection and top_k.
  template <typename Method, typename QueryRequest>
  void RunQuery(const httplib::Request& request,
                Method method,
                QueryRequest* query,
                Json about,
                httplib::Response& response) const {
    if (query->collection().empty()) {
      return ReplyError(response, absl::InvalidArgumentError("pick a collection"));
    }
    absl::StatusOr<int> top_k = TopK(request, options_.max_top_k);
    if (!top_k.ok()) return ReplyError(response, top_k.status());
    query->set_top_k(*top_k);
    v1::QueryResponse answer;
    // A query changes nothing: retrying it while the coordinator restarts
    // is safe.
    if (absl::Status s = Ask(method, *query, &answer); !s.ok()) {
      return ReplyError(response, s);
    }
    about.Set("features", static_cast<uint64_t>(answer.query_features()));
    Json body = Json::MakeObject();
    body.Set("collection", query->collection());
    body.Set("query", std::move(about));
    body.Set("results", ResultsJson(answer));
    ReplyJson(response, body);
  }

  v1::Coordinator::Stub* coordinator_;
  WebGatewayOptions options_;
};

}  // namespace

absl::Status WebGatewayOptions::Validate() const {
  if (port < 0 || port > 65535) {
    return absl::InvalidArgumentError(absl::StrCat("web: port must be in [0, 65535], got ", port));
  }
  if (max_upload_bytes < 1024 || max_upload_bytes > (std::size_t{1} << 30)) {
    return absl::InvalidArgumentError(
        absl::StrCat("web: max_upload_bytes must be in [1 KiB, 1 GiB], got ", max_upload_bytes));
  }
  if (max_top_k < 1 || max_top_k > 1000) {
    return absl::InvalidArgumentError(
        absl::StrCat("web: max_top_k must be in [1, 1000], got ", max_top_k));
  }
  if (call_deadline <= absl::ZeroDuration()) {
    return absl::InvalidArgumentError("web: call_deadline must be positive");
  }
  if (tls.cert_file.empty() != tls.key_file.empty()) {
    return absl::InvalidArgumentError("web: --web_tls_cert and --web_tls_key go together");
  }
  if (!open && !IsLoopback(host) && (token_file.empty() || tls.cert_file.empty())) {
    return absl::InvalidArgumentError(absl::StrCat(
        "web: --web_host=", host, " serves the API beyond this machine: give it a token "
        "(--web_token_file) and TLS (--web_tls_cert, --web_tls_key), or --web_open on a private "
        "network or behind a proxy that authenticates"));
  }
  return absl::OkStatus();
}

bool IsLoopback(const std::string& host) {
  return host == "localhost" || host == "::1" || absl::StartsWith(host, "127.");
}

absl::StatusOr<std::unique_ptr<WebGateway>> WebGateway::Start(v1::Coordinator::Stub* coordinator,
                                                              const WebGatewayOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  std::unique_ptr<WebGateway> gateway(new WebGateway());
  MESHSEEK_ASSIGN_OR_RETURN(gateway->server_, MakeServer(options.tls));
  httplib::Server& server = *gateway->server_;
  std::string token;
  if (!options.token_file.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(token, rpc::ReadTokenFile(options.token_file, "--web_token_file"));
  }
  // Before the body is read: a caller without the token uploads nothing.
  // The scheme's name is case-insensitive (RFC 6750), the token is not.
  server.set_pre_routing_handler([token](const httplib::Request& q, httplib::Response& r) {
    const std::string given = q.get_header_value("Authorization");
    if (token.empty() || !absl::StartsWith(q.path, "/api/") ||
        (absl::StartsWithIgnoreCase(given, "Bearer ") &&
         rpc::ConstantTimeEquals(given.substr(7), token))) {
      return httplib::Server::HandlerResponse::Unhandled;
    }
    r.set_header("WWW-Authenticate", "Bearer realm=\"meshseek\"");
    ReplyError(r, absl::UnauthenticatedError(
                      q.has_header("Authorization")
                          ? "wrong bearer token"
                          : "this gateway wants a bearer token (Authorization: Bearer ...)"));
    return httplib::Server::HandlerResponse::Handled;
  });
  server.set_payload_max_length(options.max_upload_bytes);
  auto handlers = std::make_shared<const Handlers>(coordinator, options);
  using httplib::Request;
  using httplib::Response;
  server.Get("/api/collections",
             [handlers](const Request& q, Response& r) { handlers->Collections(q, r); });
  server.Post("/api/query",
              [handlers](const Request& q, Response& r) { handlers->QueryWithFile(q, r); });
  server.Get("/api/query",
             [handlers](const Request& q, Response& r) { handlers->QueryWithModel(q, r); });
  server.Post("/api/query_image",
              [handlers](const Request& q, Response& r) { handlers->QueryWithImage(q, r); });
  server.Get("/api/thumbnail",
             [handlers](const Request& q, Response& r) { handlers->Thumbnail(q, r); });
  server.Get(R"(/[A-Za-z0-9_.\-]*)",
             [handlers](const Request& q, Response& r) { handlers->Asset(q, r); });
  // httplib answers an over-long body with 413 and no text: say why.
  server.set_error_handler([max = options.max_upload_bytes](const Request&, Response& r) {
    if (r.status == 413 && r.body.empty()) {
      ReplyError(r,
                 absl::ResourceExhaustedError(absl::StrCat(
                     "the file is larger than this gateway's limit of ", max, " bytes")));
    }
  });
  server.set_exception_handler([](const Request&, Response& r, std::exception_ptr) {
    ReplyError(r, absl::InternalError("internal error in the web gateway"));
  });
  MESHSEEK_ASSIGN_OR_RETURN(gateway->port_,
                            rpc::BindHttpServer(&server, options.host, options.port, "web"));
  gateway->thread_ = rpc::ServeHttpInBackground(&server);
  return gateway;
}

WebGateway::~WebGateway() { Stop(); }

void WebGateway::Stop() {
  if (server_ != nullptr) server_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace meshseek::cli
