// The gateway against a stand-in coordinator: routes, the JSON it answers,
// the upload paths (a mesh read here and sent on as bytes, a picture sent on
// as is), the errors a page shows, the built-in assets, and who may call it:
// loopback by default, the bearer token, HTTPS with a throwaway certificate
// (deploy/make-certs.sh, openssl).
#include "cli/web_gateway.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/geometry/mesh_io.h"
#include "common/geometry/test_meshes.h"
#include "common/render/thumbnail.h"
#include "common/rpc/client.h"
#include "common/rpc/server.h"
#include "absl/strings/str_cat.h"

namespace meshseek::cli {
namespace {

class FakeCoordinator final : public v1::Coordinator::Service {
 public:
  grpc::Status ListCollections(grpc::ServerContext*,
                               const v1::ListCollectionsRequest*,
                               v1::ListCollectionsResponse* response) override {
    v1::Collection* c = response->add_collections();
    c->set_name("shapes");
    c->set_models(3);
    c->set_indexed(3);
    c->set_codebook_id("shapes@build-1");
    v1::ParamValue* method = c->mutable_params()->add_values();
    method->set_name("method");
    method->set_value("rld");
    return grpc::Status::OK;
  }
  grpc::Status Query(grpc::ServerContext*,
                     const v1::QueryRequest* request,
                     v1::QueryResponse* response) override {
    if (request->collection() != "shapes") {
      return grpc::Status(grpc::StatusCode::NOT_FOUND, "no collection 'x'");
    }
    last_file_ = request->mesh().file().data();
    last_model_ = request->model_id();
    response->set_query_features(42);
    for (uint32_t i = 0; i < std::min<uint32_t>(request->top_k(), 3); ++i) {
      v1::ScoredModel* m = response->add_results();
      m->set_model_id(i == 0 && !last_model_.empty() ? last_model_ : "m" + std::to_string(i));
      m->set_label(i < 2 ? "cube" : "ball");
      m->set_distance(0.5f * static_cast<float>(i));
    }
    return grpc::Status::OK;
  }
  grpc::Status QueryByImage(grpc::ServerContext*,
                            const v1::QueryByImageRequest* request,
                            v1::QueryResponse* response) override {
    last_image_ = request->image();
    response->add_results()->set_model_id("m2");
    return grpc::Status::OK;
  }
  grpc::Status GetThumbnail(grpc::ServerContext*,
                            const v1::GetThumbnailRequest* request,
                            v1::Thumbnail* response) override {
    if (request->model_id() != "m0") return grpc::Status(grpc::StatusCode::NOT_FOUND, "no model");
    response->set_png("\x89PNG fake");
    return grpc::Status::OK;
  }
  std::string last_file_;
  std::string last_image_;
  std::string last_model_;
};

class WebGatewayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rpc::ServerOptions options;
    options.address = "127.0.0.1:0";
    auto server = rpc::RpcServer::Start("fake-coordinator", {&coordinator_}, options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = *std::move(server);
    stub_ = v1::Coordinator::NewStub(
        rpc::MakeChannel("127.0.0.1:" + std::to_string(server_->port()), rpc::ChannelOptions()));
    ASSERT_NO_FATAL_FAILURE(Restart(Options()));
  }
  static WebGatewayOptions Options() {
    WebGatewayOptions web;
    web.port = 0;
    web.max_upload_bytes = 64 << 10;
    return web;
  }
  // A gateway with `web` in place of the running one, and a plain HTTP client of it.
  void Restart(const WebGatewayOptions& web) {
    if (gateway_) gateway_->Stop();
    auto gateway = WebGateway::Start(stub_.get(), web);
    ASSERT_TRUE(gateway.ok()) << gateway.status();
    gateway_ = *std::move(gateway);
    client_ = std::make_unique<httplib::Client>("127.0.0.1", gateway_->port());
  }
  void TearDown() override {
    if (gateway_) gateway_->Stop();
    if (server_) server_->Shutdown();
  }

  httplib::Result Upload(const std::string& name, const std::string& content, int top_k = 2) {
    httplib::MultipartFormDataItems form = {
        {"collection", "shapes", "", ""},
        {"top_k", std::to_string(top_k), "", ""},
        {"mesh", content, name, "application/octet-stream"},
    };
    return client_->Post("/api/query", form);
  }

  httplib::Result UploadPicture(const std::string& content) {
    httplib::MultipartFormDataItems form = {
        {"collection", "shapes", "", ""},
        {"image", content, "chair.png", "image/png"},
    };
    return client_->Post("/api/query_image", form);
  }

  FakeCoordinator coordinator_;
  std::unique_ptr<rpc::RpcServer> server_;
  std::unique_ptr<v1::Coordinator::Stub> stub_;
  std::unique_ptr<WebGateway> gateway_;
  std::unique_ptr<httplib::Client> client_;
};

std::string CubeOff() {
  const TriangleMesh cube = testing_meshes::Cube();
  std::ostringstream off;
  off << "OFF\n" << cube.vertices.size() << " " << cube.triangles.size() << " 0\n";
  for (const Vec3f& v : cube.vertices) off << v.x << " " << v.y << " " << v.z << "\n";
  for (const Triangle& t : cube.triangles)
    off << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  return off.str();
}

TEST(WebGatewayOptionsTest, DefaultsAreValidAndBoundsAreChecked) {
  EXPECT_TRUE(WebGatewayOptions().Validate().ok());
  EXPECT_TRUE(IsLoopback(WebGatewayOptions().host));
  WebGatewayOptions options;
  options.max_top_k = 0;
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
  options = {};
  options.port = 70000;
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(WebGatewayTest, APortInUseIsUnavailable) {
  WebGatewayOptions web;
  web.host = "127.0.0.1";
  web.port = gateway_->port();
  auto second = WebGateway::Start(stub_.get(), web);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kUnavailable) << second.status();
}

TEST_F(WebGatewayTest, ServesThePageAndItsAssets) {
  auto page = client_->Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("id=\"results\""), std::string::npos);
  EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
  auto script = client_->Get("/app.js");
  ASSERT_TRUE(script);
  EXPECT_EQ(script->status, 200);
  EXPECT_NE(script->body.find("/api/query"), std::string::npos);
  EXPECT_EQ(client_->Get("/nothing.html")->status, 404);
}

TEST_F(WebGatewayTest, ListsCollections) {
  auto answer = client_->Get("/api/collections");
  ASSERT_TRUE(answer);
  EXPECT_EQ(answer->status, 200);
  EXPECT_NE(answer->body.find(R"("name":"shapes")"), std::string::npos) << answer->body;
  EXPECT_NE(answer->body.find(R"("method":"rld")"), std::string::npos);
  EXPECT_NE(answer->body.find(R"("built":true)"), std::string::npos);
}

TEST_F(WebGatewayTest, UploadedFileIsReadDrawnAndSentOnAsItsBytes) {
  const std::string off = CubeOff();
  auto answer = Upload("cube.off", off);
  ASSERT_TRUE(answer);
  ASSERT_EQ(answer->status, 200) << answer->body;
  EXPECT_EQ(coordinator_.last_file_, off);
  EXPECT_NE(answer->body.find(R"("model_id":"m0")"), std::string::npos) << answer->body;
  EXPECT_NE(answer->body.find(R"("rank":2)"), std::string::npos);
  EXPECT_EQ(answer->body.find(R"("rank":3)"), std::string::npos);  // top_k 2
  EXPECT_NE(answer->body.find(R"("features":42)"), std::string::npos);
  EXPECT_NE(answer->body.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(answer->body.find("8 vertices"), std::string::npos) << answer->body;
}

TEST_F(WebGatewayTest, QueriesWithAModelOfTheCollection) {
  auto answer = client_->Get("/api/query?collection=shapes&model_id=m7&top_k=3");
  ASSERT_TRUE(answer);
  ASSERT_EQ(answer->status, 200) << answer->body;
  EXPECT_EQ(coordinator_.last_model_, "m7");
  EXPECT_NE(answer->body.find(R"("model_id":"m7")"), std::string::npos);
}

TEST_F(WebGatewayTest, BadInputGetsAClearErrorWithTheRightStatus) {
  auto bad = Upload("broken.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_NE(bad->body.find("broken.off"), std::string::npos) << bad->body;
  EXPECT_TRUE(coordinator_.last_file_.empty());  // refused before asking

  auto big = Upload("big.off", std::string(100 << 10, 'x'));
  ASSERT_TRUE(big);
  EXPECT_EQ(big->status, 413);
  EXPECT_NE(big->body.find("limit"), std::string::npos) << big->body;

  auto top_k = Upload("cube.off", CubeOff(), 0);
  ASSERT_TRUE(top_k);
  EXPECT_EQ(top_k->status, 400);
  EXPECT_NE(top_k->body.find("top_k"), std::string::npos);

  auto unknown = client_->Get("/api/query?collection=x&model_id=m1");
  ASSERT_TRUE(unknown);
  EXPECT_EQ(unknown->status, 404);
  EXPECT_NE(unknown->body.find("no collection 'x'"), std::string::npos);

  auto no_model = client_->Get("/api/query?collection=shapes");
  ASSERT_TRUE(no_model);
  EXPECT_EQ(no_model->status, 400);
}

TEST_F(WebGatewayTest, ServesThumbnailsAsPng) {
  auto found = client_->Get("/api/thumbnail?collection=shapes&model_id=m0");
  ASSERT_TRUE(found);
  EXPECT_EQ(found->status, 200);
  EXPECT_EQ(found->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(found->body, "\x89PNG fake");
  EXPECT_EQ(client_->Get("/api/thumbnail?collection=shapes&model_id=zz")->status, 404);
}

TEST(WebGatewayOptionsTest, AnExposedGatewayNeedsATokenAndTlsOrOpen) {
  EXPECT_TRUE(IsLoopback("localhost"));
  EXPECT_TRUE(IsLoopback("127.0.0.2"));
  EXPECT_TRUE(IsLoopback("::1"));
  EXPECT_FALSE(IsLoopback("0.0.0.0"));
  EXPECT_FALSE(IsLoopback("10.0.0.7"));
  WebGatewayOptions options;
  options.host = "0.0.0.0";
  const absl::Status exposed = options.Validate();
  EXPECT_EQ(exposed.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(exposed.message().find("--web_token_file"), std::string::npos) << exposed;
  options.token_file = "/token";
  EXPECT_FALSE(options.Validate().ok());  // a token in clear text across the network
  options.tls = {"/tls.crt", "/tls.key", ""};
  EXPECT_TRUE(options.Validate().ok());
  options.tls.key_file.clear();
  EXPECT_NE(options.Validate().message().find("--web_tls_key"), std::string::npos);
  options = {};
  options.host = "0.0.0.0";
  options.open = true;
  EXPECT_TRUE(options.Validate().ok());
}

TEST_F(WebGatewayTest, APictureIsSentOnAsItsBytes) {
  const std::string png = "\x89PNG\r\n\x1a\n not decoded here";
  auto answer = UploadPicture(png);
  ASSERT_TRUE(answer);
  ASSERT_EQ(answer->status, 200) << answer->body;
  EXPECT_EQ(coordinator_.last_image_, png);
  EXPECT_NE(answer->body.find(R"("model_id":"m2")"), std::string::npos) << answer->body;
  EXPECT_NE(answer->body.find(R"("name":"chair.png")"), std::string::npos) << answer->body;

  auto empty = UploadPicture("");
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty->status, 400);
  EXPECT_NE(empty->body.find("chair.png: empty file"), std::string::npos) << empty->body;
  auto no_image = client_->Post("/api/query_image", httplib::MultipartFormDataItems{
                                                        {"collection", "shapes", "", ""}});
  ASSERT_TRUE(no_image);
  EXPECT_EQ(no_image->status, 400);
}

// Writes `token` to a file of the test's temporary folder; its path.
std::string TokenFile(const std::string& token) {
  const std::string path = ::testing::TempDir() + "/meshseek_web_token";
  std::ofstream(path) << token << "\n";
  return path;
}

TEST_F(WebGatewayTest, ATokenIsWantedOnEveryApiCallButNotForThePage) {
  WebGatewayOptions web = Options();
  web.token_file = TokenFile("s3cret");
  ASSERT_NO_FATAL_FAILURE(Restart(web));
  auto bare = client_->Get("/api/collections");
  ASSERT_TRUE(bare);
  EXPECT_EQ(bare->status, 401);
  EXPECT_EQ(bare->get_header_value("WWW-Authenticate"), "Bearer realm=\"meshseek\"");
  EXPECT_NE(bare->body.find("bearer token"), std::string::npos) << bare->body;
  auto wrong = client_->Get("/api/thumbnail?collection=shapes&model_id=m0",
                            {{"Authorization", "Bearer s3cre"}});
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->status, 401);
  EXPECT_NE(wrong->body.find("wrong bearer token"), std::string::npos) << wrong->body;
  auto upload = Upload("cube.off", CubeOff());  // refused before it reaches the coordinator
  ASSERT_TRUE(upload);
  EXPECT_EQ(upload->status, 401);
  EXPECT_TRUE(coordinator_.last_file_.empty());
  EXPECT_EQ(client_->Get("/")->status, 200);
  EXPECT_EQ(client_->Get("/app.js")->status, 200);

  client_->set_bearer_token_auth("s3cret");
  auto listed = client_->Get("/api/collections");
  ASSERT_TRUE(listed);
  EXPECT_EQ(listed->status, 200) << listed->body;
  EXPECT_EQ(Upload("cube.off", CubeOff())->status, 200);
  EXPECT_EQ(client_->Get("/api/collections", {{"Authorization", "bearer s3cret"}})->status, 200);
  EXPECT_EQ(client_->Get("/api/collections", {{"Authorization", "Bearer S3CRET"}})->status, 401);

  web.token_file = TokenFile("   \n");
  EXPECT_EQ(WebGateway::Start(stub_.get(), web).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(WebGatewayTest, ServesHttpsWithItsCertificate) {
  const char* source = std::getenv("MESHSEEK_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "run through ctest (MESHSEEK_SOURCE_DIR)";
  const std::string dir = ::testing::TempDir() + "/meshseek_web_tls";
  std::filesystem::remove_all(dir);
  const std::string command = absl::StrCat(source, "/deploy/make-certs.sh ", dir, " >/dev/null");
  ASSERT_EQ(std::system(command.c_str()), 0) << command << " (is openssl installed?)";
  WebGatewayOptions web = Options();
  web.host = "0.0.0.0";
  web.tls = {dir + "/tls.crt", dir + "/tls.key", ""};
  web.token_file = dir + "/token";
  ASSERT_NO_FATAL_FAILURE(Restart(web));

  httplib::SSLClient tls("localhost", gateway_->port());
  tls.set_ca_cert_path((dir + "/ca.crt").c_str());
  tls.enable_server_certificate_verification(true);
  std::ifstream token_in(dir + "/token");
  std::string token;
  token_in >> token;
  tls.set_bearer_token_auth(token.c_str());
  auto listed = tls.Get("/api/collections");
  ASSERT_TRUE(listed) << httplib::to_string(listed.error());
  EXPECT_EQ(listed->status, 200) << listed->body;
  EXPECT_FALSE(client_->Get("/api/collections"));  // plain HTTP gets no answer

  web.tls.key_file = dir + "/absent.key";
  auto missing = WebGateway::Start(stub_.get(), web);
  EXPECT_NE(missing.status().message().find("--web_tls_key"), std::string::npos) << missing.status();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace meshseek::cli
