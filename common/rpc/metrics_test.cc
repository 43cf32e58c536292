// Metrics as Prometheus scrapes them, over HTTP from a real server's
// endpoint: calls counted by method and status code (unary, streaming, and a
// made-up method under "unknown"), latency histograms, and gauges computed at
// scrape time, summed by labels and gone with their handle.
#include "common/rpc/metrics.h"

#include <httplib.h>

#include <future>
#include <string>

#include "absl/strings/str_cat.h"
#include "common/rpc/client.h"
#include "common/rpc/free_port.h"
#include "common/rpc/metrics_scrape.h"
#include "common/rpc/server.h"
#include "grpcpp/generic/generic_stub.h"
#include "gtest/gtest.h"
#include "meshseek/v1/index.grpc.pb.h"

namespace meshseek::rpc {
namespace {

// AddModel succeeds, ExportModels streams one model; every other method is
// UNIMPLEMENTED (the generated base class).
class FakeIndex final : public v1::Index::Service {
 public:
  grpc::Status AddModel(grpc::ServerContext*,
                        const v1::AddModelRequest*,
                        v1::AddModelResponse* response) override {
    response->set_collection_size(1);
    return grpc::Status::OK;
  }
  grpc::Status ExportModels(grpc::ServerContext*,
                            const v1::ExportModelsRequest*,
                            grpc::ServerWriter<v1::IndexedModel>* writer) override {
    writer->Write(v1::IndexedModel());
    return grpc::Status::OK;
  }
};

std::string Calls(const std::string& method, const std::string& code) {
  return absl::StrCat("meshseek_rpc_calls_total{code=\"",
                      code,
                      "\",method=\"",
                      method,
                      "\",service=\"metrics_test\"}");
}

TEST(MetricsOptionsTest, MetricsAddressMustBeHostPortOfAnotherPort) {
  ServerOptions options;
  options.address = "127.0.0.1:5000";
  options.metrics_address = "127.0.0.1:0";
  EXPECT_TRUE(options.Validate().ok());
  options.metrics_address = "127.0.0.1:9464";
  EXPECT_TRUE(options.Validate().ok());
  options.metrics_address = "nowhere";
  EXPECT_FALSE(options.Validate().ok());
  options.metrics_address = "127.0.0.1:5000";
  EXPECT_FALSE(options.Validate().ok());
  options.metrics_address = "127.0.0.1:70000";
  EXPECT_FALSE(options.Validate().ok());
}

TEST(MetricsTest, CallsAreCountedByMethodAndCodeAndTimed) {
  FakeIndex index;
  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.metrics_address = absl::StrCat("127.0.0.1:", FreeLoopbackPort());
  auto server = RpcServer::Start("metrics_test", {&index}, options);
  ASSERT_TRUE(server.ok()) << server.status();
  const int port = (*server)->metrics_port();
  ASSERT_GT(port, 0);
  const std::string add = "/meshseek.v1.Index/AddModel";
  const std::string before = Scrape(port);
  EXPECT_EQ(SeriesValue(before, Calls(add, "OK")), -1) << before;

  auto channel = MakeChannel(absl::StrCat("127.0.0.1:", (*server)->port()));
  auto stub = v1::Index::NewStub(channel);
  for (int i = 0; i < 2; ++i) {
    grpc::ClientContext context;
    v1::AddModelResponse response;
    ASSERT_TRUE(stub->AddModel(&context, v1::AddModelRequest(), &response).ok());
  }
  {
    grpc::ClientContext context;
    v1::SearchResponse response;
    EXPECT_EQ(stub->Search(&context, v1::SearchRequest(), &response).error_code(),
              grpc::StatusCode::UNIMPLEMENTED);
  }
  {
    grpc::ClientContext context;
    auto reader = stub->ExportModels(&context, v1::ExportModelsRequest());
    v1::IndexedModel model;
    while (reader->Read(&model)) {
    }
    ASSERT_TRUE(reader->Finish().ok());
  }
  {
    // A method no service defines is counted, under "unknown".
    grpc::GenericStub generic(channel);
    grpc::ClientContext context;
    grpc::Slice empty("");
    grpc::ByteBuffer request(&empty, 1), response;
    std::promise<grpc::Status> done;
    generic.UnaryCall(&context,
                      "/made.Up/Method",
                      grpc::StubOptions(),
                      &request,
                      &response,
                      [&done](grpc::Status status) { done.set_value(status); });
    EXPECT_EQ(done.get_future().get().error_code(), grpc::StatusCode::UNIMPLEMENTED);
  }

  const std::string after = Scrape(port);
  EXPECT_EQ(SeriesValue(after, Calls(add, "OK")), 2) << after;
  EXPECT_EQ(SeriesValue(after, Calls("/meshseek.v1.Index/Search", "UNIMPLEMENTED")), 1) << after;
  EXPECT_EQ(SeriesValue(after, Calls("/meshseek.v1.Index/ExportModels", "OK")), 1) << after;
  EXPECT_EQ(SeriesValue(after, Calls("unknown", "UNIMPLEMENTED")), 1) << after;
  const std::string labels = absl::StrCat("method=\"", add, "\",service=\"metrics_test\"");
  EXPECT_EQ(SeriesValue(after, absl::StrCat("meshseek_rpc_duration_seconds_count{", labels, "}")),
            2)
      << after;
  EXPECT_EQ(
      SeriesValue(after,
                  absl::StrCat("meshseek_rpc_duration_seconds_bucket{", labels, ",le=\"+Inf\"}")),
      2)
      << after;
  EXPECT_GT(SeriesValue(after, absl::StrCat("meshseek_rpc_duration_seconds_sum{", labels, "}")), 0)
      << after;
}

TEST(MetricsTest, ScrapeGaugesAreSummedByLabelsAndGoWithTheirHandle) {
  auto endpoint = MetricsEndpoint::Start(absl::StrCat("127.0.0.1:", FreeLoopbackPort()));
  ASSERT_TRUE(endpoint.ok()) << endpoint.status();
  const int port = (*endpoint)->port();
  auto shard = [](double models) {
    return [models]() -> absl::StatusOr<std::vector<GaugeSample>> {
      return std::vector<GaugeSample>{{{{"collection", "c"}}, models}};
    };
  };
  auto one = ScrapeGauge::Register("meshseek_test_models", "models", shard(2));
  auto two = ScrapeGauge::Register("meshseek_test_models", "models", shard(3));
  auto broken = ScrapeGauge::Register("meshseek_test_broken", "fails", [] {
    return absl::StatusOr<std::vector<GaugeSample>>(absl::InternalError("no database"));
  });
  const std::string series = "meshseek_test_models{collection=\"c\"}";
  std::string text = Scrape(port);
  EXPECT_EQ(SeriesValue(text, series), 5) << text;
  EXPECT_NE(text.find("# TYPE meshseek_test_models gauge"), std::string::npos) << text;
  EXPECT_EQ(text.find("meshseek_test_broken{"), std::string::npos) << text;
  two.reset();
  EXPECT_EQ(SeriesValue(Scrape(port), series), 2);
  one.reset();
  EXPECT_EQ(SeriesValue(Scrape(port), series), -1);
}

TEST(MetricsTest, APortInUseIsUnavailable) {
  auto first = MetricsEndpoint::Start("127.0.0.1:0");
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_GT((*first)->port(), 0);
  auto second = MetricsEndpoint::Start(absl::StrCat("127.0.0.1:", (*first)->port()));
  EXPECT_EQ(second.status().code(), absl::StatusCode::kUnavailable) << second.status();
}

}  // namespace
}  // namespace meshseek::rpc
