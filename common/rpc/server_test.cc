// RpcServer's admission: bursts beyond the server threads wait in the queue
// and are served; only calls beyond the queue are refused, with
// RESOURCE_EXHAUSTED; health checks answer while every slot is taken. A port
// in use is refused.
#include "common/rpc/server.h"

#include <atomic>
#include <map>
#include <thread>
#include <vector>

#include "common/rpc/client.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "gtest/gtest.h"
#include "meshseek/v1/index.grpc.pb.h"

namespace meshseek::rpc {
namespace {

// An index whose AddModel takes `delay` and records how many run at once.
class SlowIndex final : public v1::Index::Service {
 public:
  explicit SlowIndex(absl::Duration delay) : delay_(delay) {}
  grpc::Status AddModel(grpc::ServerContext*,
                        const v1::AddModelRequest*,
                        v1::AddModelResponse* response) override {
    const int now = ++running_;
    int seen = max_running_.load();
    while (now > seen && !max_running_.compare_exchange_weak(seen, now)) {
    }
    std::this_thread::sleep_for(absl::ToChronoMilliseconds(delay_));
    --running_;
    response->set_collection_size(1);
    return grpc::Status::OK;
  }
  int max_running() const { return max_running_.load(); }

 private:
  const absl::Duration delay_;
  std::atomic<int> running_{0};
  std::atomic<int> max_running_{0};
};

// `calls` concurrent AddModel calls, not retried; the count of each status code.
std::map<grpc::StatusCode, int> Burst(int port, int calls) {
  std::vector<grpc::StatusCode> codes(calls);
  std::vector<std::thread> threads;
  auto stub = v1::Index::NewStub(MakeChannel(absl::StrCat("127.0.0.1:", port)));
  for (int i = 0; i < calls; ++i) {
    threads.emplace_back([&, i] {
      grpc::ClientContext context;
      SetDeadline(&context, absl::Seconds(60));
      context.set_wait_for_ready(true);
      v1::AddModelRequest request;
      v1::AddModelResponse response;
      codes[i] = stub->AddModel(&context, request, &response).error_code();
    });
  }
  for (auto& t : threads) t.join();
  std::map<grpc::StatusCode, int> count;
  for (grpc::StatusCode c : codes) ++count[c];
  return count;
}

TEST(ServerOptionsTest, DefaultsAreValid) { EXPECT_TRUE(ServerOptions().Validate().ok()); }

TEST(ServerOptionsTest, RejectsBadQueueAndSecurity) {
  ServerOptions options;
  options.max_queued_calls = -1;
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
  options = ServerOptions();
  options.security.tls.ca_file = "/ca.pem";  // client certificates without a server certificate
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
  options = ServerOptions();
  options.security.token_file = "/token";  // a token in plaintext
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
}

TEST(ServerAdmissionTest, BurstBeyondTheThreadsIsQueuedAndServed) {
  SlowIndex service(absl::Milliseconds(100));
  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.max_threads = 16;
  auto server = RpcServer::Start("slow", {&service}, options);
  ASSERT_TRUE(server.ok()) << server.status();
  const auto codes = Burst((*server)->port(), 96);
  EXPECT_EQ(codes.size(), 1u);
  EXPECT_EQ(codes.count(grpc::StatusCode::OK) ? codes.at(grpc::StatusCode::OK) : 0, 96);
  EXPECT_LE(service.max_running(), 16);
}

TEST(ServerAdmissionTest, TwoThreadsServeSixtyFourCallsOneAfterAnother) {
  SlowIndex service(absl::Milliseconds(20));
  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.max_threads = 2;
  options.max_queued_calls = 64;
  auto server = RpcServer::Start("slow", {&service}, options);
  ASSERT_TRUE(server.ok()) << server.status();
  const auto codes = Burst((*server)->port(), 64);
  EXPECT_EQ(codes.count(grpc::StatusCode::OK) ? codes.at(grpc::StatusCode::OK) : 0, 64);
  EXPECT_LE(service.max_running(), 2);
}

TEST(ServerAdmissionTest, BeyondTheQueueCallsAreRefusedAndHealthStillAnswers) {
  SlowIndex service(absl::Milliseconds(1500));
  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.max_threads = 2;
  options.max_queued_calls = 4;
  auto server = RpcServer::Start("slow", {&service}, options);
  ASSERT_TRUE(server.ok()) << server.status();
  std::map<grpc::StatusCode, int> codes;
  std::thread burst([&] { codes = Burst((*server)->port(), 24); });
  // While the burst holds every slot, the health service still answers.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  auto health = grpc::health::v1::Health::NewStub(
      MakeChannel(absl::StrCat("127.0.0.1:", (*server)->port())));
  grpc::ClientContext context;
  SetDeadline(&context, absl::Seconds(1));
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = health->Check(&context, {}, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  burst.join();
  EXPECT_GE(codes[grpc::StatusCode::OK], 2);
  EXPECT_GE(codes[grpc::StatusCode::RESOURCE_EXHAUSTED], 1);
  EXPECT_EQ(codes[grpc::StatusCode::OK] + codes[grpc::StatusCode::RESOURCE_EXHAUSTED], 24);
  EXPECT_LE(service.max_running(), 2);
}

// A second server on a port in use is refused, naming the address: with
// gRPC's default SO_REUSEPORT both would listen, each answering some of
// the calls meant for the other.
TEST(ServerPortTest, APortInUseIsUnavailable) {
  SlowIndex service(absl::Milliseconds(1));
  ServerOptions options;
  options.address = "127.0.0.1:0";
  auto first = RpcServer::Start("first", {&service}, options);
  ASSERT_TRUE(first.ok()) << first.status();
  options.address = absl::StrCat("127.0.0.1:", (*first)->port());
  SlowIndex other(absl::Milliseconds(1));
  auto second = RpcServer::Start("second", {&other}, options);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_NE(second.status().message().find(options.address), std::string::npos)
      << second.status();
}

}  // namespace
}  // namespace meshseek::rpc
