// The embedded stack's one metrics endpoint, scraped over HTTP after a few
// models are ingested and built through the coordinator: the coordinator's
// gauges count them by state, the index's count them indexed, and the calls
// of the inner services (the coordinator's calls to extract and index) are
// served by the same endpoint, labelled by service.
#include <httplib.h>

#include <filesystem>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "services/embedded/embedded_stack.h"
#include "common/rpc/client.h"
#include "common/wire/convert.h"
#include "common/rpc/free_port.h"
#include "common/rpc/metrics_scrape.h"
#include "common/synth/synthetic_benchmark.h"
#include "gtest/gtest.h"
#include "meshseek/v1/coordinator.grpc.pb.h"

namespace meshseek {
namespace {

using rpc::Scrape;
using rpc::SeriesValue;

TEST(EmbeddedMetricsTest, OneEndpointCountsModelsByStateIndexedModelsAndEveryServicesCalls) {
  const std::string dir = ::testing::TempDir() + "/meshseek_metrics";
  std::filesystem::remove_all(dir);
  const int metrics_port = rpc::FreeLoopbackPort();
  auto stack = EmbeddedStack::Start(dir, 2, 0, {}, {}, metrics_port);
  ASSERT_TRUE(stack.ok()) << stack.status();
  auto stub = v1::Coordinator::NewStub(rpc::MakeChannel((*stack)->coordinator_address()));
  {
    grpc::ClientContext context;
    v1::CreateCollectionRequest request;
    request.set_name("metered");
    request.mutable_params()->set_method(v1::FEATURE_METHOD_DLD);
    request.mutable_params()->set_num_points(64);
    request.mutable_params()->set_vocabulary(8);
    v1::Collection response;
    const grpc::Status status = stub->CreateCollection(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  SyntheticBenchmarkOptions synth;
  synth.models_per_class = 2;
  synth.classes = {"snake"};
  auto models = MakeSyntheticModels(synth);
  ASSERT_TRUE(models.ok()) << models.status();
  {
    grpc::ClientContext context;
    auto stream = stub->Ingest(&context);
    for (std::size_t i = 0; i < models->size(); ++i) {
      v1::IngestRequest request;
      request.set_collection("metered");
      request.set_model_id(absl::StrCat("m", i));
      wire::MeshToProto((*models)[i].mesh, request.mutable_mesh()->mutable_mesh());
      ASSERT_TRUE(stream->Write(request));
      v1::IngestAck ack;
      ASSERT_TRUE(stream->Read(&ack));
    }
    stream->WritesDone();
    const grpc::Status status = stream->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  const std::string pending =
      "meshseek_coordinator_models{collection=\"metered\",state=\"pending\"}";
  const std::string extracted =
      "meshseek_coordinator_models{collection=\"metered\",state=\"extracted\"}";
  const std::string failed = "meshseek_coordinator_models{collection=\"metered\",state=\"failed\"}";
  std::string text;
  for (absl::Time give_up = absl::Now() + absl::Seconds(60); absl::Now() < give_up;) {
    text = Scrape(metrics_port);
    if (SeriesValue(text, extracted) == 2) break;
    absl::SleepFor(absl::Milliseconds(200));
  }
  EXPECT_EQ(SeriesValue(text, extracted), 2) << text;
  EXPECT_EQ(SeriesValue(text, pending), 0) << text;
  EXPECT_EQ(SeriesValue(text, failed), 0) << text;

  v1::JobStatus job;
  {
    grpc::ClientContext context;
    v1::BuildRequest request;
    request.set_collection("metered");
    const grpc::Status status = stub->Build(&context, request, &job);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  for (absl::Time give_up = absl::Now() + absl::Seconds(60);
       job.state() == v1::JOB_STATE_RUNNING && absl::Now() < give_up;) {
    absl::SleepFor(absl::Milliseconds(200));
    grpc::ClientContext context;
    v1::JobRequest request;
    request.set_job_id(job.job_id());
    ASSERT_TRUE(stub->GetJob(&context, request, &job).ok());
  }
  ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.message();

  text = Scrape(metrics_port);
  EXPECT_EQ(SeriesValue(text, "meshseek_index_models{collection=\"metered\"}"), 2) << text;
  EXPECT_GE(SeriesValue(text,
                        "meshseek_rpc_calls_total{code=\"OK\",method=\"/meshseek.v1.Coordinator/"
                        "Ingest\",service=\"coordinator\"}"),
            1)
      << text;
  // The coordinator's own calls to the inner services, on the same endpoint
  // (DLD-SIFT samples inside extract: no resample call).
  for (const char* service : {"extract", "codebook", "index"}) {
    EXPECT_NE(text.find(absl::StrCat("service=\"", service, "\"}")), std::string::npos)
        << service << "\n"
        << text;
  }
  stack->reset();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace meshseek
