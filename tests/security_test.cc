// TLS, mutual TLS and bearer tokens over real connections, with a throwaway
// CA made by deploy/make-certs.sh (openssl) at test time, and a second,
// unrelated CA playing the stranger:
//   - the coordinator of an embedded stack with TLS and a token refuses
//     plaintext, a missing token and a wrong one (UNAUTHENTICATED), serves
//     the right one, and answers health checks without a token;
//   - its channels to the services use mutual TLS: a model ingested through
//     it is extracted by services that require client certificates;
//   - a service requiring client certificates refuses a client without one
//     and a client whose certificate another CA signed;
//   - the plaintext health-only port answers while the main port wants TLS.
#include <cstdlib>
#include <filesystem>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "services/embedded/embedded_stack.h"
#include "common/rpc/client.h"
#include "common/wire/convert.h"
#include "common/rpc/server.h"
#include "common/rpc/status.h"
#include "common/synth/synthetic_benchmark.h"
#include "gmock/gmock.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "gtest/gtest.h"
#include "meshseek/v1/coordinator.grpc.pb.h"
#include "meshseek/v1/index.grpc.pb.h"
#include "services/index/index_grpc.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

class SecurityTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(::testing::TempDir() + "/meshseek_security");
    std::filesystem::remove_all(*dir_);
    const char* source = std::getenv("MESHSEEK_SOURCE_DIR");
    ASSERT_NE(source, nullptr) << "run through ctest (MESHSEEK_SOURCE_DIR)";
    for (const char* ca : {"ca", "stranger"}) {
      const std::string command =
          absl::StrCat(source, "/deploy/make-certs.sh ", *dir_, "/", ca, " >/dev/null");
      ASSERT_EQ(std::system(command.c_str()), 0) << command << " (is openssl installed?)";
    }
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static std::string File(const std::string& ca, const std::string& name) {
    return absl::StrCat(*dir_, "/", ca, "/", name);
  }
  static rpc::TlsOptions Tls(const std::string& ca) {
    return {File(ca, "tls.crt"), File(ca, "tls.key"), File(ca, "ca.crt")};
  }
  // A client of `address` as the CLI makes it; `ca` empty: plaintext.
  static rpc::ChannelOptions Client(const std::string& ca,
                                    const std::string& token_file = "",
                                    bool client_certificate = false) {
    rpc::ClientSecurityOptions security;
    if (!ca.empty()) security.tls.ca_file = File(ca, "ca.crt");
    if (client_certificate) {
      security.tls.cert_file = File(ca, "tls.crt");
      security.tls.key_file = File(ca, "tls.key");
    }
    security.token_file = token_file;
    auto options = rpc::WithClientSecurity(security);
    EXPECT_TRUE(options.ok()) << options.status();
    options->retry_service = "";
    return *options;
  }
  static absl::Status GetCollection(const std::string& address, const rpc::ChannelOptions& channel) {
    auto stub = v1::Coordinator::NewStub(rpc::MakeChannel(address, channel));
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(5));
    v1::GetCollectionRequest request;
    request.set_name("absent");
    v1::Collection response;
    return rpc::FromGrpcStatus(stub->GetCollection(&context, request, &response));
  }
  static absl::Status Health(const std::string& address, const rpc::ChannelOptions& channel) {
    auto stub = grpc::health::v1::Health::NewStub(rpc::MakeChannel(address, channel));
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(5));
    grpc::health::v1::HealthCheckResponse response;
    return rpc::FromGrpcStatus(stub->Check(&context, {}, &response));
  }
  static absl::Status ListModels(int port, const rpc::ChannelOptions& channel) {
    auto stub = v1::Index::NewStub(rpc::MakeChannel(absl::StrCat("127.0.0.1:", port), channel));
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(5));
    v1::ListModelsRequest request;
    request.set_collection("c");
    v1::ListModelsResponse response;
    return rpc::FromGrpcStatus(stub->ListModels(&context, request, &response));
  }

  static std::string* dir_;
};
std::string* SecurityTest::dir_ = nullptr;

TEST_F(SecurityTest, CoordinatorWantsTlsAndTheTokenButHealthIsOpen) {
  EmbeddedSecurity security;
  security.coordinator.tls.cert_file = File("ca", "tls.crt");
  security.coordinator.tls.key_file = File("ca", "tls.key");
  security.coordinator.token_file = File("ca", "token");
  security.internal = Tls("ca");
  auto stack = EmbeddedStack::Start(*dir_ + "/data", 2, 0, security);
  ASSERT_TRUE(stack.ok()) << stack.status();
  const std::string address = (*stack)->coordinator_address();

  // Plaintext: the TLS port does not talk to it.
  EXPECT_EQ(GetCollection(address, Client("")).code(), absl::StatusCode::kUnavailable);
  // TLS without a token, with a wrong one, with the right one.
  absl::Status missing = GetCollection(address, Client("ca"));
  EXPECT_EQ(missing.code(), absl::StatusCode::kUnauthenticated) << missing;
  EXPECT_THAT(std::string(missing.message()), HasSubstr("bearer token"));
  absl::Status wrong = GetCollection(address, Client("ca", File("stranger", "token")));
  EXPECT_EQ(wrong.code(), absl::StatusCode::kUnauthenticated) << wrong;
  EXPECT_THAT(std::string(wrong.message()), HasSubstr("wrong bearer token"));
  absl::Status right = GetCollection(address, Client("ca", File("ca", "token")));
  EXPECT_EQ(right.code(), absl::StatusCode::kNotFound) << right;  // served: no such collection
  // A server certificate from another CA is not trusted.
  EXPECT_EQ(GetCollection(address, Client("stranger", File("ca", "token"))).code(),
            absl::StatusCode::kUnavailable);
  // Health needs TLS but no token.
  absl::Status health = Health(address, Client("ca"));
  EXPECT_TRUE(health.ok()) << health;

  // The coordinator reaches services that require client certificates: a
  // model ingested through it gets extracted (resample and extract calls).
  auto stub = v1::Coordinator::NewStub(rpc::MakeChannel(address, Client("ca", File("ca", "token"))));
  {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(10));
    v1::CreateCollectionRequest request;
    request.set_name("secure");
    request.mutable_params()->set_method(v1::FEATURE_METHOD_DLD);
    request.mutable_params()->set_num_points(64);
    request.mutable_params()->set_vocabulary(8);
    v1::Collection response;
    const grpc::Status status = stub->CreateCollection(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  SyntheticBenchmarkOptions synth;
  synth.models_per_class = 1;
  synth.classes = {"snake"};
  auto models = MakeSyntheticModels(synth);
  ASSERT_TRUE(models.ok()) << models.status();
  {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(10));
    auto stream = stub->Ingest(&context);
    v1::IngestRequest request;
    request.set_collection("secure");
    request.set_model_id("m0");
    wire::MeshToProto((*models)[0].mesh, request.mutable_mesh()->mutable_mesh());
    ASSERT_TRUE(stream->Write(request));
    stream->WritesDone();
    v1::IngestAck ack;
    EXPECT_TRUE(stream->Read(&ack));
    const grpc::Status status = stream->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  v1::Collection info;
  for (absl::Time give_up = absl::Now() + absl::Seconds(30); absl::Now() < give_up;) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(5));
    v1::GetCollectionRequest request;
    request.set_name("secure");
    ASSERT_TRUE(stub->GetCollection(&context, request, &info).ok());
    if (info.extracted() == 1) break;
    absl::SleepFor(absl::Milliseconds(100));
  }
  EXPECT_EQ(info.extracted(), 1u) << "the coordinator could not reach the mutual-TLS services";
}

TEST_F(SecurityTest, ServiceWithMutualTlsRefusesStrangersAndPlaintext) {
  IndexServiceOptions index_options{*dir_ + "/index", 1};
  auto index = IndexService::Create(index_options);
  ASSERT_TRUE(index.ok()) << index.status();
  rpc::ServerOptions options;
  options.address = "127.0.0.1:0";
  options.health_address = "127.0.0.1:0";
  options.security.tls = Tls("ca");
  IndexGrpc grpc(index->get());
  auto server = rpc::RpcServer::Start("index", {&grpc}, options);
  ASSERT_TRUE(server.ok()) << server.status();
  const int port = (*server)->port();

  absl::Status served = ListModels(port, Client("ca", "", /*client_certificate=*/true));
  EXPECT_TRUE(served.ok() || served.code() == absl::StatusCode::kNotFound) << served;
  EXPECT_EQ(ListModels(port, Client("ca")).code(), absl::StatusCode::kUnavailable)
      << "no client certificate";
  // The stranger's certificate, presented while trusting the right server CA.
  rpc::ClientSecurityOptions stranger;
  stranger.tls = {File("stranger", "tls.crt"), File("stranger", "tls.key"), File("ca", "ca.crt")};
  auto stranger_channel = rpc::WithClientSecurity(stranger);
  ASSERT_TRUE(stranger_channel.ok());
  EXPECT_EQ(ListModels(port, *stranger_channel).code(), absl::StatusCode::kUnavailable)
      << "client certificate signed by another CA";
  EXPECT_EQ(ListModels(port, Client("")).code(), absl::StatusCode::kUnavailable) << "plaintext";

  // The health-only port: plaintext, health and nothing else.
  ASSERT_NE((*server)->health_port(), 0);
  const std::string health = absl::StrCat("127.0.0.1:", (*server)->health_port());
  absl::Status probe = Health(health, Client(""));
  EXPECT_TRUE(probe.ok()) << probe;
  EXPECT_EQ(ListModels((*server)->health_port(), Client("")).code(),
            absl::StatusCode::kUnimplemented);
}

TEST_F(SecurityTest, BadFilesAreNamedAtStart) {
  EmbeddedSecurity security;
  security.coordinator.tls.cert_file = File("ca", "tls.crt");
  security.coordinator.tls.key_file = File("ca", "tls.key");
  security.coordinator.token_file = File("ca", "no-such-token");
  auto stack = EmbeddedStack::Start(*dir_ + "/data-bad", 1, 0, security);
  ASSERT_FALSE(stack.ok());
  EXPECT_THAT(std::string(stack.status().message()), HasSubstr(File("ca", "no-such-token")));
}

}  // namespace
}  // namespace meshseek
