#include "services/coordinator/dispatcher.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/rpc/server.h"
#include "meshseek/v1/extract.grpc.pb.h"

namespace meshseek {
namespace {

TEST(DispatcherPolicyTest, PermanentErrorsAreTheModelsOwn) {
  EXPECT_TRUE(IsPermanentModelError(absl::InvalidArgumentError("")));
  EXPECT_TRUE(IsPermanentModelError(absl::DataLossError("")));
  EXPECT_TRUE(IsPermanentModelError(absl::FailedPreconditionError("")));
  EXPECT_FALSE(IsPermanentModelError(absl::UnavailableError("")));
  EXPECT_FALSE(IsPermanentModelError(absl::InternalError("")));
  EXPECT_FALSE(IsPermanentModelError(absl::DeadlineExceededError("")));
}

TEST(DispatcherPolicyTest, BackoffDoublesUpToItsBound) {
  CoordinatorOptions options;  // 2 s doubling to 1 min
  EXPECT_EQ(RetryBackoff(options, 1), absl::Seconds(2));
  EXPECT_EQ(RetryBackoff(options, 2), absl::Seconds(4));
  EXPECT_EQ(RetryBackoff(options, 5), absl::Seconds(32));
  EXPECT_EQ(RetryBackoff(options, 6), absl::Minutes(1));
  EXPECT_EQ(RetryBackoff(options, 60), absl::Minutes(1));
}

// An extract worker that rejects "bad" (the mesh's fault), is always
// unavailable for "flaky" (as a worker that crashes on it) and extracts the
// rest.
class FakeExtract final : public v1::Extract::Service {
 public:
  grpc::Status Extract(grpc::ServerContext*, const v1::ExtractRequest* request,
                       v1::ExtractResponse* response) override {
    ++calls;
    if (request->model_id() == "bad") {
      return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "mesh gives no features");
    }
    if (request->model_id() == "flaky") {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, "worker crashed");
    }
    response->mutable_features()->set_count(3);
    return grpc::Status::OK;
  }
  std::atomic<int> calls{0};
};

TEST(DispatcherTest, ModelsEndExtractedOrFailedWithTheirReasonAndThenAllIsIdle) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "dispatcher";
  std::filesystem::remove_all(dir);
  FakeExtract extract;
  rpc::ServerOptions server_options;
  server_options.address = "127.0.0.1:0";
  auto server = rpc::RpcServer::Start("fake-extract", {&extract}, server_options);
  ASSERT_TRUE(server.ok()) << server.status();
  const std::string target = absl::StrCat("127.0.0.1:", (*server)->port());

  CoordinatorOptions options;
  options.data_dir = dir.string();
  options.resample_target = options.extract_target = options.codebook_target =
      options.index_target = target;
  options.max_in_flight = 2;
  options.call_attempts = 1;
  options.model_attempts = 3;
  options.retry_backoff = absl::Milliseconds(20);
  options.max_retry_backoff = absl::Milliseconds(40);
  ASSERT_TRUE(options.Validate().ok());
  auto store = CoordinatorStore::Open(options.data_dir, 1);
  ASSERT_TRUE(store.ok()) << store.status();
  v1::PipelineParams params;
  params.set_method(v1::FEATURE_METHOD_DLD);
  ASSERT_TRUE((*store)->CreateCollections({{"c", params}}).ok());
  const std::string job = (*store)->NewJob("ingest", "c", 0).value();
  for (const char* id : {"good", "bad", "flaky"}) {
    ASSERT_TRUE((*store)->AddModel({"c"}, id, "", v1::Mesh().SerializeAsString(), job).ok());
  }
  ASSERT_TRUE((*store)->AddModel({"c"}, "damaged", "", "\xff\xff not a mesh", job).ok());
  ASSERT_TRUE((*store)->CloseIngestStream(job).ok());

  std::atomic<bool> stop{false};
  Workers workers(options, &stop);
  LiveIndex live(store->get(), &workers);
  Dispatcher dispatcher(store->get(), &workers, &live, options, &stop);
  const absl::Time start = absl::Now();
  dispatcher.Start();
  while ((*store)->PendingCount() > 0 && absl::Now() - start < absl::Seconds(20)) {
    absl::SleepFor(absl::Milliseconds(10));
  }
  EXPECT_LT(absl::Now() - start, absl::Seconds(5)) << "every model should end within seconds";
  const v1::JobStatus status = (*store)->GetJob(job).value();
  EXPECT_EQ(status.state(), v1::JOB_STATE_FAILED);
  EXPECT_EQ(status.message(), "3 of 4 models failed");

  v1::ListCollectionModelsRequest list;
  list.set_collection("c");
  const v1::ListCollectionModelsResponse models = (*store)->ListModels(list).value();
  ASSERT_EQ(models.models_size(), 4);
  EXPECT_EQ(models.models(0).state(), v1::MODEL_STATE_EXTRACTED);
  EXPECT_EQ(models.models(0).features(), 3u);
  EXPECT_EQ(models.models(1).state(), v1::MODEL_STATE_FAILED);
  EXPECT_EQ(models.models(1).attempts(), 1u);  // permanent: no retry
  EXPECT_EQ(models.models(1).error(), "INVALID_ARGUMENT: mesh gives no features");
  EXPECT_EQ(models.models(2).state(), v1::MODEL_STATE_FAILED);
  EXPECT_EQ(models.models(2).attempts(), 3u);
  EXPECT_EQ(models.models(2).error(), "gave up after 3 attempts: UNAVAILABLE: worker crashed");
  EXPECT_EQ(models.models(3).state(), v1::MODEL_STATE_FAILED);
  EXPECT_EQ(models.models(3).error(),
            "DATA_LOSS: the stored mesh does not parse (damaged database?)");

  // Nothing is retried any more.
  const int calls = extract.calls;
  absl::SleepFor(absl::Milliseconds(300));
  EXPECT_EQ(extract.calls, calls);
  stop = true;
  dispatcher.Join();
  (*server)->Shutdown();
}

}  // namespace
}  // namespace meshseek
